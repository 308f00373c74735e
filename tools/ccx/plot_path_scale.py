#!/usr/bin/env python3
"""Plot of docs/validation/path_scale/path_scale.csv: mean normalized-path error against the
reference, per run, over the comparison scale (Gaussian sigma along x), for both
normalizations (docs/validation.md, "At what scale does the reference converge").

usage: plot_path_scale.py CSV OUT.png [--reference A_pad]
"""
import argparse
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("csv")
    ap.add_argument("out")
    ap.add_argument("--reference", default="A_pad")
    a = ap.parse_args()
    rows = [r for r in csv.DictReader(open(a.csv)) if r["reference"] == a.reference and r["merkel_side"] == "both"]
    if not rows:
        sys.exit(f"plot_path_scale: no two-sided rows against {a.reference} in {a.csv}")
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
    for ax, norm, title in ((axes[0], "map", "divided by each map's maximum (the paper's)"),
                            (axes[1], "path", "divided by each path's own maximum")):
        for run in sorted({r["run"] for r in rows}):
            pts = sorted((float(r["smooth_mm"]), float(r["mean_abs_err"])) for r in rows
                         if r["run"] == run and r["normalize"] == norm)
            if pts:
                style = "k--o" if run.startswith("A") else "-o"
                ax.plot([p[0] for p in pts], [p[1] for p in pts], style,
                        label=run + (" (mesh band)" if run.startswith("A") else ""))
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("comparison scale: Gaussian sigma along x [mm]")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel(f"normalized path, mean abs. error vs {a.reference}")
    axes[1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(a.out, dpi=120)
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
