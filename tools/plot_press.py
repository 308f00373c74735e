#!/usr/bin/env python3
"""Plots of a press run (or several overlaid): the analogues of the paper's Figs 6, 7, 10-12.

usage: plot_press.py DIR [DIR ...] [--labels A,B,...] [--out OUTDIR]

Each DIR holds force_displacement.csv, merkel_sed.csv and sed_path.csv as written by
`sedbridge press` (or by the CalculiX reference tool). Legends name the model (from
merkel_sed_step.csv, which `press` writes), else the folder; --labels overrides both.
Writes into OUTDIR:
  force_displacement.png   Fig. 6   force vs displacement
  area_force.png           Fig. 7   contact area vs force
  merkel_sed.png           Fig. 10  SED map at the Merkel layer (viridis, perceptually uniform),
                                    with the step, displacement and force it shows and the max
                                    (one panel per run, one shared colour scale)
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
from matplotlib.ticker import MaxNLocator  # noqa: E402


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in (rows[0].keys() if rows else [])}


def read_step_info(d, fd, target_force_N=1.0):
    """(model or None, step, displacement_mm, force_N, exact) of the step merkel_sed.csv shows.

    `press` writes merkel_sed_step.csv; for other producers (the CalculiX tool) the step whose
    force is closest to target_force_N is assumed, as `press` chooses it (exact = False).
    """
    path = os.path.join(d, "merkel_sed_step.csv")
    if os.path.exists(path):
        with open(path, newline="") as f:
            row = next(csv.DictReader(f))
        return row["model"], int(float(row["step"])), float(row["displacement_mm"]), float(row["force_N"]), True
    if not fd.get("force_N"):
        return None, None, None, None, False
    i = min(range(len(fd["force_N"])), key=lambda k: abs(fd["force_N"][k] - target_force_N))
    return None, int(fd["step"][i]), fd["displacement_mm"][i], fd["force_N"][i], False


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dirs", nargs="+")
    ap.add_argument("--labels", default="")
    ap.add_argument("--out", default=None)
    ap.add_argument("--path-y", type=float, default=2.0, help="y of the path line on the map [mm]")
    a = ap.parse_args()
    given = a.labels.split(",") if a.labels else []
    out = a.out or a.dirs[0]
    os.makedirs(out, exist_ok=True)
    runs, infos = [], []
    for i, d in enumerate(a.dirs):
        try:
            fd = read_csv(os.path.join(d, "force_displacement.csv"))
            info = read_step_info(d, fd)
            # The model, not the output folder's name ("press_Bc"), unless the user said otherwise.
            label = given[i] if i < len(given) else (f"model {info[0]}" if info[0] else os.path.basename(os.path.normpath(d)))
            runs.append((label, fd,
                         read_csv(os.path.join(d, "merkel_sed.csv")),
                         read_csv(os.path.join(d, "sed_path.csv"))))
            infos.append(info)
        except (OSError, KeyError, IndexError, ValueError, StopIteration) as e:
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
    sheets = []
    for _, _, sed, _ in runs:
        # The pad-facing sheet: vertices above the median depth of the layer in z_pad.
        zs = sorted(sed["z_mm"])
        zcut = zs[len(zs) // 2]
        sheets.append(list(zip(*[(x, y, v) for x, y, z, v in zip(sed["x_mm"], sed["y_mm"], sed["z_mm"], sed["sed_Pa"])
                                 if z >= zcut])))
    vmax = max(max(sh[2]) for sh in sheets) or 1.0
    # Round contour levels (0, 200, 400, ... Pa), so the colour bar reads without arithmetic.
    levels = MaxNLocator(nbins=12).tick_values(0.0, vmax)
    fig, axes = plt.subplots(1, n, figsize=(4.0 * n + 1.0, 5.0), squeeze=False, constrained_layout=True)
    cs = None
    for ax, (label, _, _, _), (xs, ys, ss), info in zip(axes[0], runs, sheets, infos):
        tri = mtri.Triangulation(xs, ys)
        # viridis: perceptually uniform and readable in grey; one scale for all panels.
        cs = ax.tricontourf(tri, ss, levels=levels, cmap="viridis", extend="neither")
        imax = max(range(len(ss)), key=lambda i: ss[i])
        ax.plot(xs[imax], ys[imax], marker="+", color="r", ms=12, mew=2)
        ax.annotate(f"max {ss[imax]:.0f} Pa", (xs[imax], ys[imax]), textcoords="offset points", xytext=(8, 8),
                    color="k", fontsize=9, bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.8))
        ax.axhline(a.path_y, color="w", lw=0.8, ls="--")
        ax.set_aspect("equal")
        ax.set_xlim(-9, 9)
        ax.set_ylim(-8, 12)
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        _, step, disp, force, exact = info
        if step is not None:
            where = f"step {step}: d = {disp:.2f} mm, F = {force:.2f} N" + ("" if exact else " (closest to 1 N)")
        else:
            where = "step unknown"
        ax.set_title(f"{label}\n{where}", fontsize=10)
    fig.suptitle("SED at the Merkel layer (pad frame; dashed: path line)", fontsize=11)
    fig.colorbar(cs, ax=axes[0].tolist(), label="SED [Pa]", shrink=0.8, fraction=0.05, pad=0.02)
    fig.savefig(os.path.join(out, "merkel_sed.png"), dpi=150, bbox_inches="tight")  # nothing clipped
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
