#!/usr/bin/env python3
"""K-fold cross-validation of the follower sensor's calibration, judged by the bridge's fidelity.

Each rig press is scored with a forward model fitted WITHOUT it: the presses are split into
K folds; for each fold, `sedbridge fit-sensor --hold-out <fold>` fits the forward model on the
other presses, and `sedbridge fidelity` runs the fold's presses through the bridge with that
model. This is the closest a lab gets, from its own calibration presses, to how the bridge
does on presses of the same sensor it was not calibrated on (docs/bridge-fidelity.md).

Usage:
  tools/rig_cross_validation.py [--sedbridge build/sedbridge] [--cases config/sensors/rig_uskin_4x4/cases.json]
                                [--profile config/sensors/uskin_4x4.yaml] [--folds 7] [--out out/rig_cv]

Each fit starts from fit-sensor's generic start (PROFILE without its forward_model block), with
PROFILE's rod_min_halfwidth_mm (calibrated apart: fit-sensor --rod-radii); the fold profile is
PROFILE with its forward_model block replaced by the fold's fit, keeping the block's keys the
fit does not write.
Folds take the presses in file order, every K-th press to the same fold, so each fold mixes
shapes. Writes OUT/cv_fidelity.csv (every press's fidelity row, with its fold), OUT/fold_N/
(the fold's fit log, profile, cases and fidelity output) and prints the per-press table
and the count within the fidelity targets. Standard library only.
"""
import argparse
import csv
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from logged_run import run_logged  # noqa: E402


def forward_model_block(text):
    """Returns (lines before forward_model:, the block's lines, lines after)."""
    lines = text.splitlines(keepends=True)
    start = next((i for i, l in enumerate(lines) if l.startswith("forward_model:")), None)
    if start is None:
        return lines, [], []
    end = start + 1
    while end < len(lines) and (lines[end].startswith(" ") or lines[end].strip() == ""):
        end += 1
    return lines[:start], lines[start:end], lines[end:]


def fold_profile(profile_text, fitted_text):
    """PROFILE with the fitted forward_model block, keeping its keys the fit does not write."""
    before, block, after = forward_model_block(profile_text)
    _, fitted, _ = forward_model_block(fitted_text)
    if not fitted:
        raise SystemExit("fit-sensor wrote no forward_model block")
    fitted_keys = {l.split(":")[0].strip() for l in fitted[1:] if l.startswith("  ") and not l.startswith("    ")}
    kept = [l for l in block[1:] if l.startswith("  ") and not l.startswith("    ")
            and l.split(":")[0].strip() not in fitted_keys and l.split(":")[0].strip() != "kernels"]
    return "".join(before) + fitted[0] + "".join(kept) + "".join(fitted[1:]) + "".join(after)


def run(fold_dir, log_name, command, fold):
    """Runs `command` with its output in fold_dir/log_name; a failure names the fold and the log."""
    run_logged(command, os.path.join(fold_dir, log_name), f"rig_cross_validation: fold {fold + 1}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sedbridge", default="build/sedbridge")
    ap.add_argument("--cases", default="config/sensors/rig_uskin_4x4/cases.json")
    ap.add_argument("--profile", default="config/sensors/uskin_4x4.yaml")
    ap.add_argument("--folds", type=int, default=7)
    ap.add_argument("--out", default="out/rig_cv")
    args = ap.parse_args()

    cases_dir = os.path.dirname(os.path.abspath(args.cases))
    try:
        cases_file = json.load(open(args.cases))
        cases = cases_file["cases"]
        # What every press shares (the stage's `protocol`) goes into each fold's file too.
        shared = {k: v for k, v in cases_file.items() if k != "cases"}
        profile_text = open(args.profile).read()
    except (OSError, ValueError, KeyError) as e:
        raise SystemExit(f"rig_cross_validation: {e}")
    if args.folds < 2 or len(cases) < 2:
        raise SystemExit(f"rig_cross_validation: --folds must be >= 2 and {args.cases} must hold >= 2 presses "
                         f"(--folds {args.folds}, {len(cases)} presses)")
    k = min(args.folds, len(cases))
    os.makedirs(args.out, exist_ok=True)
    # Each fit starts from fit-sensor's generic start, not from the profile's fit of all presses.
    before, block, after = forward_model_block(profile_text)
    generic = os.path.join(args.out, "profile_without_forward_model.yaml")
    with open(generic, "w") as g:
        g.write("".join(before) + "".join(after))
    fit_extra = []
    for line in block:
        if line.strip().startswith("rod_min_halfwidth_mm:"):
            fit_extra = ["--rod-min-halfwidth-mm", line.split(":")[1].split("#")[0].strip()]
    rows = []
    t0 = time.time()
    for f in range(k):
        fold = [c for i, c in enumerate(cases) if i % k == f]
        d = os.path.join(args.out, f"fold_{f}")
        os.makedirs(d, exist_ok=True)
        logs = ",".join(c["log"] for c in fold)
        print(f"[{time.time() - t0:5.0f} s] fold {f + 1}/{k}: fit without {logs}", file=sys.stderr, flush=True)
        run(d, "fit.log", [args.sedbridge, "fit-sensor", "--cases", args.cases, "--profile", generic,
                           "--hold-out", logs, "--out", os.path.join(d, "fitted.yaml")] + fit_extra, f)
        profile = os.path.join(d, "profile.yaml")
        with open(profile, "w") as p:
            p.write(fold_profile(profile_text, open(os.path.join(d, "fitted.yaml")).read()))
        fold_cases = [dict(c, log=os.path.join(cases_dir, c["log"])) for c in fold]
        with open(os.path.join(d, "cases.json"), "w") as cj:
            json.dump({**shared, "cases": fold_cases}, cj, indent=1)
        print(f"[{time.time() - t0:5.0f} s] fold {f + 1}/{k}: fidelity of the held-out presses", file=sys.stderr,
              flush=True)
        run(d, "fidelity.log", [args.sedbridge, "fidelity", "--cases", os.path.join(d, "cases.json"), "--profile",
                                profile, "--out", os.path.join(d, "fidelity"), "--no-plots"], f)
        for r in csv.DictReader(open(os.path.join(d, "fidelity", "fidelity.csv"))):
            r["fold"] = str(f)
            rows.append(r)

    rows.sort(key=lambda r: r["case"])
    keys = ["fold"] + [key for key in rows[0].keys() if key != "fold"]
    with open(os.path.join(args.out, "cv_fidelity.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)

    def yes(v):
        return v.strip().lower() in ("1", "true", "yes")

    print(f"{'case':10} fold {'object':9} {'R_mm':>5} {'F_N':>5} | {'recon':9} {'R_mm':>5} | "
          f"{'peak':>5} {'L2':>5} {'off':>5} {'region':>6} | within")
    scored = within = within_region = 0
    for r in rows:
        valid = yes(r["truth_valid"])
        ok = yes(r["recon_within_targets"])
        region_ok = (valid and 0.8 <= float(r["recon_peak_ratio"]) <= 1.25 and float(r["recon_rel_l2"]) <= 0.25
                     and float(r["recon_peak_region_offset_mm"]) <= 1.0)
        scored += valid
        within += valid and ok
        within_region += region_ok
        print(f"{r['case']:10} {r['fold']:>4} {r['shape']:9} {float(r['radius_mm']):5.2f} {float(r['force_N']):5.2f} | "
              f"{r['recon_shape']:9} {float(r['recon_radius_mm']):5.2f} | {float(r['recon_peak_ratio']):5.2f} "
              f"{float(r['recon_rel_l2']):5.2f} {float(r['recon_peak_offset_mm']):5.2f} "
              f"{float(r['recon_peak_region_offset_mm']):6.2f} | {'yes' if ok else ('no truth' if not valid else 'no')}")
    print(f"each press scored with a forward model fitted without it ({k} folds): within all three targets "
          f"{within} of {scored} scored ({within_region} by peak region); {time.time() - t0:.0f} s")
    print(f"wrote {os.path.join(args.out, 'cv_fidelity.csv')}")


if __name__ == "__main__":
    main()
