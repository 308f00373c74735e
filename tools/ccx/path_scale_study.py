#!/usr/bin/env python3
"""At what spatial scale does the reference converge, and is B or C closer to it there?
(docs/validation.md, "At what scale does the reference converge").

usage: path_scale_study.py [--dir docs/validation/path_scale] [--sedbridge-run DIR] [--out CSV]

Compares normalized SED paths (compare_paths.py's path_errors) for every combination of
  Merkel value: both sides of the epidermis-dermis interface (the definition used
               everywhere), the epidermis side, the dermis side (read_results.py --merkel-side);
  normalization: each map's maximum (the paper's Table III) or each path's own maximum;
  scale:       Gaussian smoothing along x, sigma 0, 0.5, 1 mm;
against the pad-refined reference A_pad, for the runs A_coarse (and A, both sides only: its
raw results are gone), B and C (ccx C3D10) and, if given, a `sedbridge press` of B. Reads
DIR/<run>[_epidermis|_dermis]/ (the press output contract) and the two-sided A / A_pad / C
folders of docs/validation; writes one CSV row per comparison.
"""
import argparse
import csv
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare_paths as cp  # noqa: E402

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
VAL = os.path.join(REPO, "docs", "validation")


def run_dirs(d, side, sedbridge):
    """{label: folder} for one Merkel-value definition; the reference first."""
    suffix = "" if side == "both" else "_" + side
    runs = {"A_pad": os.path.join(VAL, "reference_A_pad_C3D10") if side == "both"
            else os.path.join(d, "A_pad_C3D10" + suffix)}
    if side == "both":
        runs["A"] = os.path.join(VAL, "reference_A_C3D10")
    runs["A_coarse"] = os.path.join(d, "A_coarse_C3D10" + suffix)
    runs["B_ccx"] = os.path.join(d, "B_C3D10" + suffix)
    runs["C_ccx"] = (os.path.join(VAL, "reference_A_C3D10", "C_C3D10") if side == "both"
                     else os.path.join(d, "C_C3D10" + suffix))
    if sedbridge and side == "both":
        runs["B_sedbridge"] = sedbridge
    return runs


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dir", default=os.path.join(VAL, "path_scale"))
    ap.add_argument("--sedbridge-run", default=None, help="`sedbridge press` output of model B (paper_press.yaml)")
    ap.add_argument("--out", default=None, help="CSV (default DIR/path_scale.csv)")
    a = ap.parse_args()
    out = a.out or os.path.join(a.dir, "path_scale.csv")
    rows = []
    for side in ("both", "epidermis", "dermis"):
        runs = run_dirs(a.dir, side, a.sedbridge_run)
        paths = {k: cp.read_cols(os.path.join(v, "sed_path.csv")) for k, v in runs.items()}
        for norm in ("map", "path"):
            for sigma in (0.0, 0.5, 1.0):
                ref = cp.prepared(paths["A_pad"], norm, sigma)
                for label, p in paths.items():
                    if label == "A_pad":
                        continue
                    mean, mx, n, lo, hi = cp.path_errors(ref, cp.prepared(p, norm, sigma))
                    rows.append(dict(reference="A_pad", merkel_side=side, normalize=norm, smooth_mm=f"{sigma:g}",
                                     run=label, mean_abs_err=f"{mean:.4f}", max_abs_err=f"{mx:.4f}",
                                     x_lo=f"{lo:g}", x_hi=f"{hi:g}"))
    with open(out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {out} ({len(rows)} rows)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
