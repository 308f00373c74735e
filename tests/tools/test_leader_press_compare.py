#!/usr/bin/env python3
"""tools/leader_press_compare on model B_coarse: an object against itself scores 1 / 0 / 0
and is within the targets, a larger sphere is not, an object off the pad exits 1 with its
press status, and bad input exits 2 naming file:line:column."""
import argparse
import os
import subprocess
import sys

parser = argparse.ArgumentParser()
parser.add_argument("--tool", required=True)
parser.add_argument("--work", required=True)
args = parser.parse_args()
os.makedirs(args.work, exist_ok=True)


def run(*extra):
    return subprocess.run([args.tool, "--model", "B_coarse", "--cache-dir", os.path.join(args.work, "cache"), *extra],
                          capture_output=True, text=True, timeout=240)


def check(condition, what, result=None):
    if not condition:
        detail = f"\nstdout:\n{result.stdout}\nstderr:\n{result.stderr}" if result else ""
        sys.exit(f"test_leader_press_compare: {what}{detail}")


def write(name, text):
    path = os.path.join(args.work, name)
    with open(path, "w") as f:
        f.write(text)
    return path


good = write("good.yaml", """force_N: 0.3
reference: [{shape: sphere, radius_mm: 3, position_mm: [0, 0, 3]}]
candidates:
  - {name: same sphere, objects: [{shape: sphere, radius_mm: 3, position_mm: [0, 0, 3]}]}
  - {name: sphere R6, objects: [{shape: sphere, radius_mm: 6, position_mm: [0, 0, 6]}]}
""")
csv_path = os.path.join(args.work, "good.csv")
maps_path = os.path.join(args.work, "good_maps.csv")
r = run("--csv", csv_path, "--maps", maps_path, good)
check(r.returncode == 0, f"exit {r.returncode} for reachable presses", r)
rows = {line.split(",")[0].strip('"'): line.strip().split(",") for line in open(csv_path).readlines()[1:]}
check(set(rows) == {"reference", "same sphere", "sphere R6"}, f"CSV rows {sorted(rows)}")
same, larger = rows["same sphere"], rows["sphere R6"]
check(same[1] == "reached" and abs(float(same[2]) - 0.3) < 1e-3, f"same sphere press {same}")
# The same object pressed again: the same answer to the press's own tolerance.
check(abs(float(same[4]) - 1) < 1e-6 and float(same[5]) < 1e-6 and same[8] == "1", f"same sphere scores {same}")
# A sphere twice as large spreads the same force: a lower, broader peak, not within.
check(float(larger[4]) < 0.8 and float(larger[5]) > 0.25 and larger[8] == "0", f"sphere R6 scores {larger}")
check("same sphere" in r.stdout and "within" in r.stdout, "table on stdout", r)
# The maps: one column per press, the reference first; its peak is the table's.
with open(maps_path) as f:
    header = f.readline().strip().split(",")
    values = [[float(v) for v in line.split(",")] for line in f if line.strip()]
check(header == ["x_mm", "y_mm", "z_mm", '"reference"', '"same sphere"', '"sphere R6"'], f"maps header {header}")
check(len(values) > 100 and all(len(v) == 6 for v in values), f"maps rows {len(values)}")
check(abs(max(v[3] for v in values) - float(rows["reference"][3])) < 1e-3 * float(rows["reference"][3]),
      "the reference map's peak is the table's")
# Its plot, where Debian's matplotlib is (the system Python; tools/setup.sh installs it).
plot = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools", "plot_leader_press_compare.py")
if subprocess.run(["/usr/bin/python3", "-c", "import matplotlib"], capture_output=True).returncode == 0:
    png = os.path.join(args.work, "good_maps.png")
    p = subprocess.run(["/usr/bin/python3", plot, maps_path, png], capture_output=True, text=True, timeout=120)
    check(p.returncode == 0 and os.path.getsize(png) > 1000, "plot_leader_press_compare.py writes the PNG", p)
    p = subprocess.run(["/usr/bin/python3", plot, csv_path], capture_output=True, text=True, timeout=120)
    check(p.returncode == 2 and "not a leader_press_compare --maps file" in p.stderr, "the plot refuses the table CSV", p)

off = write("off.yaml", """force_N: 0.3
reference: [{shape: sphere, radius_mm: 3, position_mm: [0, 0, 3]}]
candidates:
  - {name: off the pad, objects: [{shape: sphere, radius_mm: 3, position_mm: [40, 0, 3]}]}
""")
r = run(off)
check(r.returncode == 1, f"exit {r.returncode} when a press cannot reach its force", r)
check("no_contact" in r.stdout, "the failed press's status in the table", r)

bad = write("bad.yaml", "force_N: 0.3\nreference: [{shape: sphere, radius_mm: 3}]\ncandidates:\n  - {objects: []}\n")
r = run(bad)
check(r.returncode == 2 and "bad.yaml:4:" in r.stderr and "name" in r.stderr, "bad input names file:line", r)
r = run("--force", "-1", good)
check(r.returncode == 2 and "--force" in r.stderr, "a negative --force is refused", r)
r = subprocess.run([args.tool, "--help"], capture_output=True, text=True)
check(r.returncode == 0 and "usage: leader_press_compare" in r.stdout, "--help", r)
print("test_leader_press_compare: ok")
