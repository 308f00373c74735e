#!/usr/bin/env python3
"""Plot of docs/validation/path_scale/path_scale.csv: mean normalized-path error against the
reference, per run, over the comparison scale (Gaussian sigma along x), for both
normalizations (docs/validation.md, "At what scale does the reference converge").

usage: plot_path_scale.py CSV OUT.png [--reference A_pad] [--side both|epidermis|dermis]
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
    ap.add_argument("--side", default="both", choices=("both", "epidermis", "dermis"),
                    help="Merkel value: both sides of the interface (default) or one side")
    a = ap.parse_args()
    rows = [r for r in csv.DictReader(open(a.csv)) if r["reference"] == a.reference and r["merkel_side"] == a.side]
    if not rows:
        sys.exit(f"plot_path_scale: no {a.side} rows against {a.reference} in {a.csv}")
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
    for ax, norm, title in ((axes[0], "map", "divided by each map's maximum (the paper's)"),
                            (axes[1], "path", "divided by each path's own maximum")):
        for run in sorted({r["run"] for r in rows}):
            pts = sorted((float(r["smooth_mm"]), float(r["mean_abs_err"])) for r in rows
                         if r["run"] == run and r["normalize"] == norm)
            if pts:
                band = run.startswith("A")  # another mesh of the reference model
                ax.plot([p[0] for p in pts], [p[1] for p in pts], ("--s" if run != "A" else "--o") if band else "-o",
                        color=("0.5" if run != "A" else "k") if band else None,
                        label=run + (" (mesh band)" if band else ""))
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("comparison scale: Gaussian sigma along x [mm]")
        ax.grid(alpha=0.3)
    side = "two-sided Merkel value" if a.side == "both" else a.side + " side"
    axes[0].set_ylabel(f"normalized path ({side}), mean abs. error vs {a.reference}", fontsize=9)
    axes[1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(a.out, dpi=120)
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
