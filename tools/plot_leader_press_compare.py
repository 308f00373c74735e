#!/usr/bin/python3
"""Side-by-side Merkel-layer SED maps of tools/leader_press_compare's presses.

Usage: plot_leader_press_compare.py MAPS.csv [OUT.png]

MAPS.csv is what `leader_press_compare --maps MAPS.csv FILE.yaml` writes (x_mm, y_mm, z_mm
in the leader's pad frame, then one column per press: the reference first). Writes OUT.png
(default: MAPS.png beside it): one panel per press, the pad seen from the object's side, one
colour scale (the reference's), each panel titled with its press and peak SED.

Run with /usr/bin/python3 (needs matplotlib; Debian: python3-matplotlib).
"""
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) < 2 or sys.argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if len(sys.argv) >= 2 else 2
    path = sys.argv[1]
    out = sys.argv[2] if len(sys.argv) > 2 else os.path.splitext(path)[0] + ".png"
    try:
        with open(path) as f:
            reader = csv.reader(f)
            header = next(reader)
            if header[:3] != ["x_mm", "y_mm", "z_mm"] or len(header) < 4:
                print(f"plot_leader_press_compare: {path}: not a leader_press_compare --maps file", file=sys.stderr)
                return 2
            rows = []
            for row in reader:
                if row:
                    rows.append([float(v) for v in row])
    except (OSError, StopIteration) as e:
        print(f"plot_leader_press_compare: {path}: {e}", file=sys.stderr)
        return 2
    except ValueError as e:
        print(f"plot_leader_press_compare: {path}:{reader.line_num}: {e}", file=sys.stderr)
        return 2
    # The pad: Merkel vertices within 6 mm of the pad plane, under a sensor's footprint.
    rows = [r for r in rows if r[2] > -6.0 and abs(r[0]) < 12 and abs(r[1]) < 14]
    names = header[3:]
    x = [r[0] for r in rows]
    y = [r[1] for r in rows]
    vmax = max(1e-9, max(r[3] for r in rows))
    cols = min(len(names), 4)
    lines = math.ceil(len(names) / cols)
    fig, axes = plt.subplots(lines, cols, figsize=(3.4 * cols, 3.4 * lines), squeeze=False, constrained_layout=True)
    sc = None
    for k, ax in enumerate(axes.flat):
        if k >= len(names):
            ax.axis("off")
            continue
        v = [r[3 + k] for r in rows]
        sc = ax.scatter(x, y, c=v, s=7, cmap="viridis", vmin=0, vmax=vmax)
        ax.set_title("%s\nmax %.0f Pa" % (names[k], max(v)), fontsize=9)
        ax.set_aspect("equal")
        ax.set_xlabel("x [mm]", fontsize=8)
        ax.set_ylabel("y [mm]", fontsize=8)
    fig.colorbar(sc, ax=axes, shrink=0.8, label="Merkel SED [Pa] (the reference's scale)")
    fig.savefig(out, dpi=90)
    plt.close(fig)
    print(f"plot_leader_press_compare: wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
