#!/usr/bin/env python3
"""Plots of a press run (or several overlaid): the analogues of the paper's Figs 6, 7, 10-12.

usage: plot_press.py DIR [DIR ...] [--labels A,B,...] [--out OUTDIR]

Each DIR holds force_displacement.csv, merkel_sed.csv and sed_path.csv as written by
`sedbridge press` (or by the CalculiX reference tool). Writes into OUTDIR:
  force_displacement.png   Fig. 6   force vs displacement
  area_force.png           Fig. 7   contact area vs force
  merkel_sed.png           Fig. 10  SED map at the Merkel layer, max annotated (one panel per run)
  sed_path.png             Fig. 11  SED along x at y = 2 mm
  sed_path_normalized.png  Fig. 12  the same normalized by each map's maximum
"""
import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.tri as mtri  # noqa: E402


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in (rows[0].keys() if rows else [])}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dirs", nargs="+")
    ap.add_argument("--labels", default="")
    ap.add_argument("--out", default=None)
    ap.add_argument("--path-y", type=float, default=2.0, help="y of the path line on the map [mm]")
    a = ap.parse_args()
    labels = a.labels.split(",") if a.labels else [os.path.basename(os.path.normpath(d)) for d in a.dirs]
    out = a.out or a.dirs[0]
    os.makedirs(out, exist_ok=True)
    runs = []
    for d, label in zip(a.dirs, labels):
        try:
            runs.append((label,
                         read_csv(os.path.join(d, "force_displacement.csv")),
                         read_csv(os.path.join(d, "merkel_sed.csv")),
                         read_csv(os.path.join(d, "sed_path.csv"))))
        except (OSError, KeyError, IndexError) as e:
            print(f"plot_press: cannot read run in {d}: {e}", file=sys.stderr)
            return 1

    fig, ax = plt.subplots(figsize=(5, 4))
    for label, fd, _, _ in runs:
        ax.plot(fd["displacement_mm"], fd["force_N"], marker=".", label=label)
    ax.set_xlabel("displacement [mm]")
    ax.set_ylabel("force [N]")
    ax.set_title("Force vs displacement")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "force_displacement.png"), dpi=120)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(5, 4))
    for label, fd, _, _ in runs:
        ax.plot(fd["force_N"], fd["contact_area_mm2"], marker=".", label=label)
    ax.set_xlabel("force [N]")
    ax.set_ylabel("contact area [mm$^2$]")
    ax.set_title("Contact area vs force")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "area_force.png"), dpi=120)
    plt.close(fig)

    n = len(runs)
    fig, axes = plt.subplots(1, n, figsize=(4.2 * n, 4.4), squeeze=False)
    for ax, (label, _, sed, _) in zip(axes[0], runs):
        # The pad-facing sheet: vertices above the median depth of the layer in z_pad.
        zs = sorted(sed["z_mm"])
        zcut = zs[len(zs) // 2]
        pts = [(x, y, s) for x, y, z, s in zip(sed["x_mm"], sed["y_mm"], sed["z_mm"], sed["sed_Pa"]) if z >= zcut]
        xs, ys, ss = zip(*pts)
        tri = mtri.Triangulation(xs, ys)
        cs = ax.tricontourf(tri, ss, levels=20, cmap="jet")
        fig.colorbar(cs, ax=ax, label="SED [Pa]")
        imax = max(range(len(ss)), key=lambda i: ss[i])
        ax.plot(xs[imax], ys[imax], "k+", ms=10)
        ax.annotate(f"max {ss[imax]:.0f} Pa", (xs[imax], ys[imax]), textcoords="offset points", xytext=(6, 6))
        ax.axhline(a.path_y, color="w", lw=0.8, ls="--")
        ax.set_aspect("equal")
        ax.set_xlim(-9, 9)
        ax.set_ylim(-8, 12)
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        ax.set_title(f"{label}: SED at the Merkel layer")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "merkel_sed.png"), dpi=120)
    plt.close(fig)

    for key, name, ylabel in (("sed_Pa", "sed_path.png", "SED [Pa]"),
                              ("sed_normalized", "sed_path_normalized.png", "normalized SED [-]")):
        fig, ax = plt.subplots(figsize=(5, 4))
        for label, _, _, path in runs:
            ax.plot(path["x_mm"], path[key], label=label)
        ax.set_xlabel("x [mm]")
        ax.set_ylabel(ylabel)
        ax.set_title(f"SED along x at y = {a.path_y:g} mm")
        ax.grid(alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(os.path.join(out, name), dpi=120)
        plt.close(fig)
    return 0


if __name__ == "__main__":
    sys.exit(main())
