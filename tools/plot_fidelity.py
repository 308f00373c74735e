#!/usr/bin/python3
"""Plots of the fidelity benchmark (written by `sedbridge fidelity --out DIR`).

Usage: plot_fidelity.py DIR

Reads DIR/fidelity.csv and DIR/maps/<case>.csv and writes
  DIR/maps/<case>.png     Merkel-layer SED under the pad, side by side: truth (object pressed
                          on the leader's model) | pressure-map bridge | reconstructed-contact
                          bridge, one colour scale (the truth's), pad frame (x lateral, y toward
                          the tip), the true object's position marked
  DIR/fidelity_summary.png  per case: peak SED ratio and relative L2 error of both bridges,
                          with the fidelity target bands
  DIR/fidelity_table.md   the same as a Markdown table (docs/bridge-fidelity.md)
  DIR/fidelity_scans.png  with `--through-press`: per press, the reconstructed contact's peak
                          SED ratio and L2 error at every scored scan over time, the true force
                          beside them, the target bands shaded (DIR/fidelity_scans.csv)

Run with /usr/bin/python3 (needs matplotlib; Debian: python3-matplotlib).
"""
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def plot_case(row, maps_dir):
    name = row["case"]
    path = os.path.join(maps_dir, name + ".csv")
    if not os.path.exists(path):
        return
    m = read(path)
    # The pad: Merkel vertices within 6 mm of the pad plane, under the sensor's footprint.
    m = [r for r in m if float(r["z_mm"]) > -6.0 and abs(float(r["x_mm"])) < 12 and abs(float(r["y_mm"])) < 14]
    x = [float(r["x_mm"]) for r in m]
    y = [float(r["y_mm"]) for r in m]
    vmax = max(1e-9, max(float(r["truth_sed_Pa"]) for r in m))
    fig, axes = plt.subplots(1, 3, figsize=(12, 4.4), constrained_layout=True)
    titles = [("truth_sed_Pa", "truth: object on the leader"),
              ("map_sed_Pa", "bridge: pressure map"),
              ("recon_sed_Pa", "bridge: reconstructed contact")]
    sc = None
    for ax, (key, title) in zip(axes, titles):
        v = [float(r[key]) for r in m]
        sc = ax.scatter(x, y, c=v, s=9, cmap="viridis", vmin=0, vmax=vmax)
        ax.set_title("%s\nmax %.0f Pa" % (title, max(v)), fontsize=10)
        ax.set_aspect("equal")
        ax.set_xlabel("x [mm]")
        if row["shape"] != "other":
            ax.plot([float(row["x_mm"])], [float(row["y_mm"])], "r+", ms=10)
    axes[0].set_ylabel("y [mm]")
    fig.colorbar(sc, ax=axes, shrink=0.8, label="Merkel SED [Pa] (truth's scale)")
    obj = row["label"]
    fig.suptitle("%s: %s, %.2f N; reconstructed %s, peak ratio map %.2f / recon %.2f"
                 % (row["case"], obj, float(row["force_N"]),
                    row["recon_shape"], float(row["map_peak_ratio"]), float(row["recon_peak_ratio"])), fontsize=10)
    fig.savefig(os.path.join(maps_dir, name + ".png"), dpi=90)
    plt.close(fig)


def plot_summary(rows, out):
    names = [r["case"].replace("press_", "") for r in rows]
    fig, (a, b) = plt.subplots(2, 1, figsize=(11, 6.5), sharex=True, constrained_layout=True)
    idx = range(len(rows))
    w = 0.38

    def clip(v):
        return min(v, 3.0) if math.isfinite(v) else 3.0
    bad = [i for i, r in enumerate(rows) if not r["truth_press"].startswith("reached")]
    for i in bad:
        for ax in (a, b):
            ax.axvspan(i - 0.5, i + 0.5, color="grey", alpha=0.25, lw=0)
    a.bar([i - w / 2 for i in idx], [clip(float(r["map_peak_ratio"])) for r in rows], w, label="pressure map")
    a.bar([i + w / 2 for i in idx], [clip(float(r["recon_peak_ratio"])) for r in rows], w, label="reconstructed contact")
    a.axhspan(0.8, 1.25, color="green", alpha=0.15, label="target 0.8-1.25")
    a.set_ylabel("peak SED ratio (bridge / truth)\n(clipped at 3; grey: no valid truth)")
    a.legend(fontsize=8, loc="upper left")
    b.bar([i - w / 2 for i in idx], [clip(float(r["map_rel_l2"])) for r in rows], w)
    b.bar([i + w / 2 for i in idx], [clip(float(r["recon_rel_l2"])) for r in rows], w)
    b.axhline(0.25, color="green", ls="--", label="target <= 0.25")
    b.set_ylabel("relative L2 error\nover the Merkel layer")
    b.set_xticks(list(idx))
    b.set_xticklabels(["%s\n%s" % (n, r["shape"][:3]) for n, r in zip(names, rows)], fontsize=8)
    b.legend(fontsize=8)
    fig.suptitle("Fidelity at the scan of peak force (%d presses)" % len(rows))
    fig.savefig(out, dpi=90)
    plt.close(fig)


def region(r, m):
    """Peak-region offset [mm] (CSVs written before it existed: the argmax offset)."""
    return float(r.get(m + "_peak_region_offset_mm") or r[m + "_peak_offset_mm"])


def write_table(rows, out):
    with open(out, "w") as f:
        f.write("| case | object | F [N] | reconstructed | truth max SED [Pa] | map: peak ratio / L2 / offset [mm] "
                "| recon: peak ratio / L2 / offset [mm] | recon peak-region offset [mm] | recon cmd L2 | truth press |\n")
        f.write("|---|---|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            obj = r["label"]
            rec = r["recon_shape"]
            if r["recon_shape"] == "two_spheres":  # recon_force_N is the pair's total
                rec += " R%.2f (%.2f, %.2f) and R%.2f (%.2f, %.2f), %.3f N" % (
                    float(r["recon_radius_mm"]), float(r["recon_x_mm"]), float(r["recon_y_mm"]),
                    float(r["recon2_radius_mm"]), float(r["recon2_x_mm"]), float(r["recon2_y_mm"]),
                    float(r["recon_force_N"]))
            else:
                if r["recon_shape"] != "flat":
                    rec += " R%.2f" % float(r["recon_radius_mm"])
                if float(r.get("recon_length_mm") or 0) > 0:  # a finite rod
                    rec += " L%.1f" % float(r["recon_length_mm"])
                rec += " (%.2f, %.2f) %.3f N" % (float(r["recon_x_mm"]), float(r["recon_y_mm"]),
                                                 float(r["recon_force_N"]))
            if r["recon_ok"] != "1":
                rec += " **fallback**"
            f.write("| %s | %s | %.2f | %s | %.0f | %.2f / %.2f / %.1f | %.2f / %.2f / %.1f | %.1f | %.2f | %s |\n" % (
                r["case"], obj, float(r["force_N"]), rec, float(r["truth_max_sed_Pa"]),
                float(r["map_peak_ratio"]), float(r["map_rel_l2"]), float(r["map_peak_offset_mm"]),
                float(r["recon_peak_ratio"]), float(r["recon_rel_l2"]), float(r["recon_peak_offset_mm"]),
                region(r, "recon"), float(r["recon_command_rel_l2"]), r["truth_press"].split(" ")[0]))
        ok = [r for r in rows if r["truth_press"].startswith("reached")]

        def within(r, m, offset):
            return (0.8 <= float(r[m + "_peak_ratio"]) <= 1.25 and float(r[m + "_rel_l2"]) <= 0.25
                    and offset(r, m) <= 1.0)

        def argmax_offset(r, m):
            return float(r[m + "_peak_offset_mm"])

        f.write("\nWith a valid truth (its press on the leader reached the force): %d of %d cases; "
                "reconstructed contact within all three targets (peak ratio 0.8-1.25, L2 <= 0.25, offset <= 1 mm): "
                "%d; pressure map: %d. With the peak-region offset instead (distance from each peak to the other "
                "field's vertices within 5 %% of its maximum; a ridge's maximum moves along it): reconstructed %d, "
                "pressure map %d.\n" % (
                    len(ok), len(rows),
                    sum(1 for r in ok if within(r, "recon", argmax_offset)),
                    sum(1 for r in ok if within(r, "map", argmax_offset)),
                    sum(1 for r in ok if within(r, "recon", region)),
                    sum(1 for r in ok if within(r, "map", region))))


def plot_through_press(scans, out):
    cases = []  # presses with a truth to score against, in order
    for r in scans:
        if r["truth_valid"] == "1" and r["case"] not in cases:
            cases.append(r["case"])
    if not cases:
        return
    cols = min(5, len(cases))
    rows_n = (len(cases) + cols - 1) // cols
    fig, axes = plt.subplots(rows_n, cols, figsize=(3.2 * cols, 2.4 * rows_n), squeeze=False, sharey=True,
                             constrained_layout=True)
    for ax in axes.flat[len(cases):]:
        ax.axis("off")
    for ax, name in zip(axes.flat, cases):
        mine = [r for r in scans if r["case"] == name and r["truth_valid"] == "1"]
        t = [float(r["t_s"]) for r in mine]
        scored = [r["recon_ok"] == "1" for r in mine]
        ax.axhspan(0.8, 1.25, color="green", alpha=0.12)
        ax.axhline(0.25, color="green", ls=":", lw=0.8)
        ax.plot(t, [min(float(r["recon_peak_ratio"]), 3.0) if ok else float("nan") for r, ok in zip(mine, scored)],
                "o-", ms=3, label="peak ratio")
        ax.plot(t, [min(float(r["recon_rel_l2"]), 3.0) if ok else 1.0 for r, ok in zip(mine, scored)], "s--", ms=3,
                label="L2 (fallback: 1)")
        f = ax.twinx()
        f.plot(t, [float(r["force_N"]) for r in mine], color="grey", lw=0.8)
        f.set_ylim(bottom=0)
        f.tick_params(labelsize=6, colors="grey")
        within = sum(r["recon_within_targets"] == "1" for r in mine)
        ax.set_title("%s: %d of %d within" % (name, within, len(mine)), fontsize=8)
        ax.tick_params(labelsize=7)
        ax.set_ylim(0, 2.5)
    axes.flat[0].legend(fontsize=6, loc="upper left")
    fig.suptitle("Through the presses: reconstructed contact against the truth at each scored scan "
                 "(grey: true force, right axis; band: peak ratio 0.8-1.25; dotted: L2 0.25)", fontsize=9)
    fig.savefig(out, dpi=80)
    plt.close(fig)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    d = sys.argv[1]
    rows = read(os.path.join(d, "fidelity.csv"))
    for r in rows:
        plot_case(r, os.path.join(d, "maps"))
    plot_summary(rows, os.path.join(d, "fidelity_summary.png"))
    write_table(rows, os.path.join(d, "fidelity_table.md"))
    print("plots: %s/fidelity_summary.png, %s/maps/*.png" % (d, d))
    scans_csv = os.path.join(d, "fidelity_scans.csv")
    if os.path.exists(scans_csv) and os.path.getmtime(scans_csv) >= os.path.getmtime(os.path.join(d, "fidelity.csv")):
        plot_through_press(read(scans_csv), os.path.join(d, "fidelity_scans.png"))
        print("plots: %s/fidelity_scans.png" % d)


if __name__ == "__main__":
    main()
