#!/usr/bin/env python3
"""tools/fidelity_envelope.py on a hand-written fidelity.csv: its counts by force band and
by object, the presses without a truth, the misses listed, the plot (where matplotlib is),
and exit 2 naming the file (and line) for a missing folder, a missing column or a bad number."""
import argparse
import os
import subprocess
import sys

parser = argparse.ArgumentParser()
parser.add_argument("--root", required=True)
parser.add_argument("--work", required=True)
args = parser.parse_args()
tool = os.path.join(args.root, "tools", "fidelity_envelope.py")
os.makedirs(args.work, exist_ok=True)

HEADER = ("case,label,shape,force_N,truth_valid,truth_press,recon_shape,recon_radius_mm,recon_peak_ratio,"
          "recon_rel_l2,recon_peak_offset_mm,recon_peak_region_offset_mm,recon_within_targets\n")
ROWS = [
    # within all three
    "random_00_sphere,sphere R5 (0 0),sphere,0.5,1,reached,sphere,5.1,1.01,0.02,0,0,1",
    # a ridge's argmax: within by the peak region only
    "random_01_rod,rod R1 yaw 0 (0 0),cylinder,0.7,1,reached,cylinder,1.1,0.95,0.05,1.9,0,0",
    # a light rod read thick: outside the peak ratio
    "random_02_rod,rod R1 yaw 30 (1 1),cylinder,0.2,1,reached,cylinder,2.9,0.6,0.39,1.5,1.5,0",
    "random_03_flat,flat,flat,2.5,1,reached,flat,0,1.0,0.01,0,0,1",
    "random_04_stroke,sphere R6 (1 1) sliding,sphere,0.4,1,reached,sphere,6,0.99,0.02,0,0,1",
    # no truth: not scored
    "random_05_sphere,sphere R3 (6.5 6.5),sphere,0.3,0,patch_edge (0.01 N at 4.5 mm),sphere,3,0,1,0,0,0",
]


def write_run(name, header, rows):
    d = os.path.join(args.work, name)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "fidelity.csv"), "w") as f:
        f.write(header + "\n".join(rows) + "\n")
    return d


def run(*extra):
    return subprocess.run([sys.executable, tool, *extra], capture_output=True, text=True, timeout=120)


def check(condition, what, result=None):
    if not condition:
        detail = f"\nstdout:\n{result.stdout}\nstderr:\n{result.stderr}" if result else ""
        sys.exit(f"test_fidelity_envelope: {what}{detail}")


good = write_run("good", HEADER, ROWS)
r = run(good)
check(r.returncode == 0, "a good run exits 0", r)
out = r.stdout
check("6 presses in 1 run(s), 5 scored; reconstructed contact within all three targets 3, by peak region 4, "
      "peak ratio and L2 4" in out, "the totals", r)
check("| 0.15-0.3 | 1 | 0 | 0 | 0 |" in out and "| 0.3-0.6 | 2 | 2 | 2 | 2 |" in out, "the light rod's band", r)
check("| 0.6-1 | 1 | 0 | 1 | 1 |" in out, "the ridge's band: within by the peak region", r)
check("| >= 2 | 1 | 1 | 1 | 1 |" in out, "the heavy flat's band", r)
check("| rod | 2 | 0 | 1 | 1 |" in out and "| stroke | 1 | 1 | 1 | 1 |" in out, "by object", r)
check("patch_edge 1" in out, "the press without a truth, by status", r)
check("read cylinder R2.90" in out and out.count(" read ") == 1, "only the peak-ratio / L2 miss listed", r)

try:
    import matplotlib  # noqa: F401
    png = os.path.join(args.work, "envelope.png")
    r = run("--plot", png, good)
    check(r.returncode == 0 and os.path.getsize(png) > 10000, "the plot is written", r)
except ImportError:
    print("no matplotlib: plot not checked")

r = run(os.path.join(args.work, "nowhere"))
check(r.returncode == 2 and "nowhere/fidelity.csv" in r.stderr, "a folder without fidelity.csv exits 2", r)
r = run(write_run("no_column", HEADER.replace(",recon_rel_l2", ""), [row for row in ROWS]))
check(r.returncode == 2 and "fidelity.csv:1: missing column(s) recon_rel_l2" in r.stderr, "a missing column", r)
r = run(write_run("bad_number", HEADER, ROWS[:2] + [ROWS[2].replace("0.2,1,reached", "abc,1,reached")]))
check(r.returncode == 2 and "fidelity.csv:4:" in r.stderr, "a bad number names its line", r)
print("test_fidelity_envelope: ok")
