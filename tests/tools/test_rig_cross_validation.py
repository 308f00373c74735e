#!/usr/bin/env python3
"""tools/rig_cross_validation.py without running a fit: the fold profile keeps what the fit
does not write and takes the fit's kernels; a failing fit-sensor names its fold and log; the
cases file's shared keys (`protocol`) reach each fold's cases file."""
import importlib.util
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
TOOL = os.path.join(ROOT, "tools", "rig_cross_validation.py")
spec = importlib.util.spec_from_file_location("cv", TOOL)
cv = importlib.util.module_from_spec(spec)
spec.loader.exec_module(cv)

PROFILE = """name: test
scan_rate_Hz: 100
forward_model:
  contact_modulus_kPa: 313.4
  rod_min_halfwidth_mm: 0.3     # calibrated apart
  kernels:
    normal: [1, 2, 3]
    spread: [1, 2, 3]
start_frames: ["201#0700"]
"""
FITTED = """forward_model:
  contact_modulus_kPa: 300.0
  pad_size_mm: 20.0
  grid_mm: 0.235
  kernels:                       # [gain, width_mm, power]
    normal: [4, 5, 6]
    spread: [7, 8, 9]
"""

failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what)


out = cv.fold_profile(PROFILE, FITTED)
check("contact_modulus_kPa: 300.0" in out and "313.4" not in out, "the fit's modulus replaces the profile's")
check("rod_min_halfwidth_mm: 0.3" in out, "rod_min_halfwidth_mm (not fitted) is kept")
check("normal: [4, 5, 6]" in out and "normal: [1, 2, 3]" not in out, "the fit's kernels replace the profile's")
check(out.startswith("name: test\nscan_rate_Hz: 100\n") and out.endswith('start_frames: ["201#0700"]\n'),
      "the keys around the block are kept in place")
check(out.count("forward_model:") == 1, "one forward_model block")

before, block, after = cv.forward_model_block(PROFILE)
check(len(block) == 6 and "".join(before) + "".join(after) == 'name: test\nscan_rate_Hz: 100\nstart_frames: ["201#0700"]\n',
      "forward_model_block splits the profile around the block")

with tempfile.TemporaryDirectory() as work:
    r = subprocess.run([sys.executable, TOOL, "--sedbridge", "/bin/false", "--out", work,
                        "--cases", os.path.join(ROOT, "config/sensors/rig_uskin_4x4/cases.json"),
                        "--profile", os.path.join(ROOT, "config/sensors/uskin_4x4.yaml")],
                       capture_output=True, text=True)
    check(r.returncode != 0 and "fold 1" in r.stderr and "fit.log" in r.stderr and "Traceback" not in r.stderr,
          f"a failing fit-sensor names its fold and log: {r.stderr.strip()}")
    r = subprocess.run([sys.executable, TOOL, "--folds", "1", "--out", work], capture_output=True, text=True, cwd=ROOT)
    check(r.returncode != 0 and "--folds" in r.stderr and "Traceback" not in r.stderr,
          f"--folds 1 is refused: {r.stderr.strip()}")

# A cases file's shared keys (the stage's `protocol`) reach each fold's cases file: a stand-in
# sedbridge whose fit-sensor writes a forward_model block and whose fidelity fails, so the
# tool stops right after writing fold 1's cases.
with tempfile.TemporaryDirectory() as work:
    fake = os.path.join(work, "fake_sedbridge")
    with open(fake, "w") as f:
        f.write("#!/bin/sh\ncmd=$1\nout=\nwhile [ $# -gt 0 ]; do [ \"$1\" = --out ] && out=$2; shift; done\n"
                "[ \"$cmd\" = fit-sensor ] && printf 'forward_model:\\n  contact_modulus_kPa: 300.0\\n' > \"$out\" && exit 0\n"
                "exit 1\n")
    os.chmod(fake, 0o755)
    cases = os.path.join(work, "cases.json")
    with open(cases, "w") as f:
        json.dump({"protocol": {"unloaded_s": 0.5},
                   "cases": [{"object": {"shape": "flat", "position_mm": [0, 0]}, "force_N": 1, "log": "a.log"},
                             {"object": {"shape": "flat", "position_mm": [0, 0]}, "force_N": 1, "log": "b.log"}]}, f)
    r = subprocess.run([sys.executable, TOOL, "--sedbridge", fake, "--out", os.path.join(work, "out"), "--folds", "2",
                        "--cases", cases, "--profile", os.path.join(ROOT, "config/sensors/uskin_4x4.yaml")],
                       capture_output=True, text=True)
    fold_cases = os.path.join(work, "out", "fold_0", "cases.json")
    check(r.returncode != 0 and "fidelity.log" in r.stderr and os.path.exists(fold_cases),
          f"the stand-in's fidelity stops the tool after fold 1's cases: {r.stderr.strip()}")
    if os.path.exists(fold_cases):
        written = json.load(open(fold_cases))
        check(written.get("protocol") == {"unloaded_s": 0.5} and len(written["cases"]) == 1 and
              os.path.isabs(written["cases"][0]["log"]), f"the fold's cases keep the protocol: {written}")

print("ok" if not failures else f"{len(failures)} failed")
sys.exit(1 if failures else 0)
