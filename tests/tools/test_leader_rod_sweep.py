#!/usr/bin/env python3
"""tools/leader_rod_sweep.py: its presses, its summary (failed and flagged presses per radius),
its errors, and one small sweep through `sedbridge fidelity` (--sedbridge BIN)."""
import argparse
import csv
import importlib.util
import math
import os
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
TOOL = os.path.join(ROOT, "tools", "leader_rod_sweep.py")
spec = importlib.util.spec_from_file_location("sweep", TOOL)
sweep = importlib.util.module_from_spec(spec)
spec.loader.exec_module(sweep)

failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what)


ap = argparse.ArgumentParser()
ap.add_argument("--sedbridge", required=True)
ap.add_argument("--work", required=True)
args = ap.parse_args()

cases = sweep.sweep_cases([0.5, 1.0], [0.3, 1.2], [(0, 0), (1, -2)], 45, "/x/press.log")
check(len(cases) == 2 * 4 * 2 * 2, "every place, yaw, force and radius")
check(sorted({c["object"]["yaw_deg"] for c in cases}) == [22.5, 67.5, 112.5, 157.5], "yaws every step from half a step")
check(all(c["object"]["shape"] == "cylinder" and c["log"] == "/x/press.log" for c in cases), "rods on the carrier log")


def row(x, yaw, force, radius, sed, valid=True):
    return {"x_mm": str(x), "y_mm": "0", "yaw_deg": str(yaw), "force_N": str(force), "radius_mm": str(radius),
            "truth_max_sed_Pa": str(sed), "truth_valid": "1" if valid else "0",
            "truth_press": "reached" if valid else "patch_edge (0.1 N at 2 mm)"}


rows = [row(0, 10, 0.3, 0.5, 3000), row(0, 10, 0.3, 1.0, 1000),   # a spike: 3 x
        row(0, 20, 0.3, 0.5, 1100), row(0, 20, 0.3, 1.0, 1000),   # smooth
        row(0, 30, 0.3, 0.5, 500, valid=False), row(0, 30, 0.3, 1.0, 1000)]  # slipped
table, counts = sweep.summarize(rows, [0.5, 1.0], 1.6)
check(len(table) == 3, "one row per pose and force")
check(counts[0.5] == {"failed": 1, "flagged": 1} and counts[1.0] == {"failed": 0, "flagged": 0},
      "a failed press and a spike are counted for their radius")
check(math.isclose(table[0]["ratio_R0.5"], 3.0) and math.isnan(table[2]["ratio_R0.5"]) and table[2]["press_R0.5"] == "patch_edge",
      "ratios to the largest radius; a failed press has none and names its status")
try:
    sweep.summarize(rows[:3], [0.5, 1.0], 1.6)
    check(False, "a pose missing a radius is an error")
except SystemExit as e:
    check("lacks radii" in str(e), "a pose missing a radius names it")


def run(*extra):
    return subprocess.run([sys.executable, TOOL, "--sedbridge", args.sedbridge, "--out", args.work, *extra],
                          capture_output=True, text=True, cwd=ROOT)


for bad, says in ((["--radii", "0.5,x"], "--radii"), (["--radii", "0.5"], "at least two"),
                  (["--yaw-step", "0"], "--yaw-step"), (["--positions", "1:2:3"], "--positions"),
                  (["--log", "/nonexistent.log"], "no such file")):
    r = run(*bad)
    check(r.returncode != 0 and says in r.stderr, f"{bad} is refused naming {says}: {r.stderr.strip()}")
r = run("--sedbridge", "/bin/false")
check(r.returncode != 0 and "exited 1" in r.stderr and "fidelity.log" in r.stderr, "a failing sedbridge names its log")

# One place and yaw, two radii, one force: the leader holds both, the table has their ratio.
with tempfile.TemporaryDirectory() as cache:
    env = dict(os.environ, OMP_NUM_THREADS="1")
    r = subprocess.run([sys.executable, TOOL, "--sedbridge", args.sedbridge, "--out", args.work, "--radii", "0.7,1.2",
                        "--forces", "0.4", "--positions", "0:0", "--yaw-step", "180", "--cache-dir", cache],
                       capture_output=True, text=True, cwd=ROOT, env=env)
check(r.returncode == 0, f"a small sweep runs: {r.stderr.strip()[-300:]}")
if r.returncode == 0:
    with open(os.path.join(args.work, "sweep.csv")) as f:
        out = list(csv.DictReader(f))
    check(len(out) == 1 and out[0]["press_R0.7"] == "reached" and out[0]["press_R1.2"] == "reached",
          "both rods reach their force")
    ratio = float(out[0]["ratio_R0.7"]) if out else float("nan")
    check(0.9 < ratio < 1.5, f"the thinner rod's peak is a little higher, not a spike: {ratio}")
    check("0.7" in r.stdout and "of 1 poses and forces" in r.stdout, "the per-radius counts are printed")

print("FAILED" if failures else "OK", len(failures))
sys.exit(1 if failures else 0)
