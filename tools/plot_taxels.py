#!/usr/bin/python3
"""Taxel heatmap of one tactile scan.

Reads the CSV written by `sedbridge decode --heatmap-png` (columns taxel, x_mm, y_mm,
pressure_kPa, shear_x_kPa, shear_y_kPa, valid, and optionally health) and draws each taxel as
a square of its sensing size coloured by normal pressure; invalid taxels are hatched grey;
a taxel that taxel health masks (health other than "healthy") is crossed out in red with the
reason, as the bridge's plots mark it; shear, when present, is drawn as arrows on one fixed
scale with a key ("shear N kPa").

usage: /usr/bin/python3 tools/plot_taxels.py TAXELS.csv OUT.png [--title T] [--size-mm W H]
Exit status 3 when matplotlib is missing (Debian: apt-get install python3-matplotlib).
"""
import argparse
import csv
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv")
    ap.add_argument("png")
    ap.add_argument("--title", default="")
    ap.add_argument("--size-mm", nargs=2, type=float, default=None, metavar=("W", "H"))
    args = ap.parse_args()
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.patches import Rectangle
    except ImportError:
        print("matplotlib is not installed for %s (Debian: apt-get install python3-matplotlib)"
              % sys.executable, file=sys.stderr)
        return 3

    rows = list(csv.DictReader(open(args.csv)))
    if not rows:
        print("no taxels in %s" % args.csv, file=sys.stderr)
        return 1
    xs = [float(r["x_mm"]) for r in rows]
    ys = [float(r["y_mm"]) for r in rows]
    ps = [float(r["pressure_kPa"]) for r in rows]
    sx = [float(r["shear_x_kPa"]) for r in rows]
    sy = [float(r["shear_y_kPa"]) for r in rows]
    valid = [r["valid"] == "1" for r in rows]
    w, h = args.size_mm if args.size_mm else (1.0, 1.0)

    healthy = [r.get("health", "") in ("", "healthy") for r in rows]
    # The colour scale of the taxels health trusts: a stuck taxel's phantom would flatten it.
    vmax = max([p for p, v, ok in zip(ps, valid, healthy) if v and ok] + [1e-9])
    cmap = plt.get_cmap("viridis")
    fig, ax = plt.subplots(figsize=(5.5, 5.5))
    for x, y, p, ok in zip(xs, ys, ps, valid):
        if ok:
            ax.add_patch(Rectangle((x - w / 2, y - h / 2), w, h, color=cmap(min(max(p, 0) / vmax, 1.0))))
        else:
            ax.add_patch(Rectangle((x - w / 2, y - h / 2), w, h, facecolor="0.8", hatch="//",
                                   edgecolor="0.5"))
    masked = [(x, y, r.get("health", "")) for x, y, r in zip(xs, ys, rows)
              if r.get("health", "") not in ("", "healthy")]
    for x, y, why in masked:
        ax.plot([x - w / 2, x + w / 2], [y - h / 2, y + h / 2], color="red", linewidth=2)
        ax.plot([x - w / 2, x + w / 2], [y + h / 2, y - h / 2], color="red", linewidth=2)
        ax.text(x, y - h / 2, "masked:\n" + why, color="red", ha="center", va="bottom", fontsize=7)
    shear_max = max([(a * a + b * b) ** 0.5 for a, b, ok in zip(sx, sy, valid) if ok] + [0.0])
    if shear_max > 0:
        # Fixed scale: the largest arrow is 0.8 taxel widths long; the key below reads it in kPa.
        key_kPa = float("%.1g" % shear_max)
        q = ax.quiver(xs, ys, sx, sy, color="white", edgecolor="k", linewidth=0.5, angles="xy",
                      scale_units="xy", scale=shear_max / (0.8 * w))
        ax.quiverkey(q, 0.05, 1.02, key_kPa, "shear %g kPa" % key_kPa, labelpos="E", coordinates="axes",
                     color="k")
    ax.set_xlim(min(xs) - w, max(xs) + w)
    ax.set_ylim(min(ys) - h, max(ys) + h)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm] (pad frame)")
    ax.set_ylabel("y [mm]")
    ax.set_title(args.title, fontsize=10, pad=22)  # pad: room for the shear key above the axes
    sm = plt.cm.ScalarMappable(cmap=cmap, norm=plt.Normalize(0, vmax))
    fig.colorbar(sm, ax=ax, label="normal pressure [kPa]", shrink=0.8)
    fig.savefig(args.png, dpi=120, bbox_inches="tight")  # nothing clipped
    return 0


if __name__ == "__main__":
    sys.exit(main())
