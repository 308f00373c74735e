#!/usr/bin/python3
"""Plots of a bridge replay (written by `sedbridge replay ... --out DIR`).

Usage: plot_bridge.py DIR [UNIT [CEILING]]

CEILING: the highest command the display can get (mapping saturation or safety max, in UNIT);
where given, the plots mark commands that reached it (the SED mapping saturated).

Reads DIR/summary.csv, DIR/peak_merkel_sed.csv, DIR/peak_command.csv, DIR/peak_taxels.csv
(and DIR/peak_display_sed.csv where the display was rendered by inverse FE) and writes
  DIR/bridge_peak.png      at the scan of peak SED: the taxel pressures on the pad (taxels
                           masked by taxel health crossed out in red, with why), the
                           Merkel-layer SED under the pad (the target), with inverse
                           rendering the SED the display produces on the leader (full FE,
                           same colour scale), the display command (pad frame: x lateral,
                           y toward the tip)
  DIR/bridge_timeline.png  force (the sensor's taxel sum, and what the leader was pressed
                           with where that differs; scans with taxels left out shaded)
                           and max Merkel SED over time, max command below

Run with /usr/bin/python3 (needs matplotlib; Debian: python3-matplotlib).
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.patches  # noqa: E402,F401


def read(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def col(rows, key):
    return [float(r[key]) for r in rows]


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        return 2
    out = sys.argv[1]
    unit = sys.argv[2] if len(sys.argv) > 2 else ""
    ceiling = float(sys.argv[3]) if len(sys.argv) > 3 else None
    summary = read(os.path.join(out, "summary.csv"))
    sed = read(os.path.join(out, "peak_merkel_sed.csv"))
    cmd = read(os.path.join(out, "peak_command.csv"))
    taxels = read(os.path.join(out, "peak_taxels.csv"))

    # Timeline.
    t0 = float(summary[0]["utime"])
    t = [(float(r["utime"]) - t0) * 1e-6 for r in summary]
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    measured = col(summary, "total_force_N")
    a1.plot(t, measured, color="tab:blue", label="sensor (sum of taxel normals)")
    # What the leader's model was pressed with: the reconstructed contact's force (fe.step
    # contact), which a real sensor's taxel sum understates (the rig's read ~0.6 of the
    # true force); the pressure map applies the taxel sum itself, so the lines coincide.
    if summary and "applied_force_N" in summary[0]:
        applied = col(summary, "applied_force_N")
        if any(abs(a - m) > 1e-3 * max(1e-9, abs(m)) for a, m in zip(applied, measured)):
            a1.plot(t, applied, color="tab:blue", ls="--", label="applied on the leader")
    # Scans with taxels left out (masked by taxel health, or invalid): shaded.
    if summary and "invalid_taxels" in summary[0]:
        out_ = [int(r["invalid_taxels"]) > 0 for r in summary]
        if any(out_):
            a1.fill_between(t, 0, max(measured + [1e-9]), where=out_, color="tab:red", alpha=0.12, step="mid",
                            label="taxels left out (%d of %d scans, up to %d)" % (
                                sum(out_), len(out_), max(int(r["invalid_taxels"]) for r in summary)))
    a1.set_ylabel("force [N]", color="tab:blue")
    a1.legend(loc="upper left", fontsize=8)
    b1 = a1.twinx()
    b1.plot(t, col(summary, "max_sed_Pa"), color="tab:red", label="max Merkel SED")
    b1.set_ylabel("max Merkel SED [Pa]", color="tab:red")
    a1.set_title("bridge: force and max Merkel-layer SED")  # replay and simulate alike
    max_cmd = col(summary, "max_command")
    a2.plot(t, max_cmd, color="tab:green", label="max command")
    if ceiling:
        at = [c >= ceiling * (1 - 1e-6) for c in max_cmd]
        a2.axhline(ceiling, color="k", ls="--", lw=0.8, label="ceiling %g %s" % (ceiling, unit))
        if any(at):
            a2.fill_between(t, 0, ceiling, where=at, color="tab:orange", alpha=0.25, step="mid",
                            label="saturated (%d of %d scans)" % (sum(at), len(at)))
        a2.legend(loc="upper left", fontsize=8)
    a2.set_ylabel("max command [%s]" % unit)
    a2.set_xlabel("time [s]")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "bridge_timeline.png"), dpi=120)
    plt.close(fig)

    # Peak frame.
    display_path = os.path.join(out, "peak_display_sed.csv")
    delivered = read(display_path) if os.path.exists(display_path) else None
    fig, axes = plt.subplots(1, 4 if delivered else 3, figsize=(17.5 if delivered else 13, 4.2))
    ax = axes[0]
    if taxels:
        s = ax.scatter(col(taxels, "x_mm"), col(taxels, "y_mm"), c=[p * 1e-3 for p in col(taxels, "pressure_Pa")],
                       s=260, marker="s", cmap="viridis")
        fig.colorbar(s, ax=ax, label="pressure [kPa]")
    contact_path = os.path.join(out, "peak_contact.csv")
    if os.path.exists(contact_path):  # fe.step contact: the reconstructed object over the taxels
        import math
        c = read(contact_path)[0]
        x, y, w = float(c["x_mm"]), float(c["y_mm"]), float(c["contact_half_width_mm"])
        style = dict(color="red", lw=1.5, ls="--" if c["fallback"] == "1" else "-")
        if c["shape"] in ("sphere", "two_spheres"):
            ax.add_patch(matplotlib.patches.Circle((x, y), w, fill=False, **style))
            ax.plot([x], [y], "r+", ms=10)
            if c["shape"] == "two_spheres":
                x2, y2 = float(c["x2_mm"]), float(c["y2_mm"])
                ax.add_patch(matplotlib.patches.Circle((x2, y2), float(c["contact2_half_width_mm"]), fill=False, **style))
                ax.plot([x2], [y2], "r+", ms=10)
        elif c["shape"] == "cylinder":
            yaw = math.radians(float(c["yaw_deg"]))
            dx, dy = math.cos(yaw), math.sin(yaw)
            half = 0.5 * float(c.get("length_mm") or 0) or 12  # 0: the rod crosses the pad
            for off in (-w, w):
                ax.plot([x - half * dx - off * dy, x + half * dx - off * dy],
                        [y - half * dy + off * dx, y + half * dy + off * dx], **style)
        elif c["shape"] == "flat":
            ax.add_patch(matplotlib.patches.Rectangle((-10, -10), 20, 20, fill=False, **style))
        if c["shape"] != "none":
            ax.set_xlim(-12, 12)
            ax.set_ylim(-12, 12)
            if c["shape"] == "two_spheres":
                what = "two spheres R %.1f / %.1f mm, %.2f + %.2f N" % (
                    float(c["radius_mm"]), float(c["radius2_mm"]), float(c["normal_force_N"]), float(c["normal_force2_N"]))
            else:
                what = "%s R %.1f mm, %.2f N" % (c["shape"], float(c["radius_mm"]), float(c["normal_force_N"]))
                if float(c.get("length_mm") or 0) > 0:
                    what += ", %.1f mm long" % float(c["length_mm"])
            ax.text(0.02, 0.02, what + (" (fallback)" if c["fallback"] == "1" else ""),
                    transform=ax.transAxes, color="red", fontsize=8)
    # Taxels taxel health masked at the peak (peak_taxels.csv's health): a red cross and why;
    # their pressure is not their reading (left out, or filled from their neighbours).
    masked = [r for r in taxels if r.get("health", "ok") not in ("ok", "drifting")]
    if masked:
        ax.scatter(col(masked, "x_mm"), col(masked, "y_mm"), s=300, marker="x", color="red", linewidths=2.5)
        for r in masked:
            ax.annotate("%s %s" % (r["taxel"], r["health"]), (float(r["x_mm"]), float(r["y_mm"])), color="red",
                        fontsize=8, xytext=(0, 9), textcoords="offset points", ha="center")
        ax.text(0.02, 0.95, "masked: " + ", ".join("%s %s" % (r["taxel"], r["health"]) for r in masked),
                transform=ax.transAxes, color="red", fontsize=8)
    ax.set_title("taxels (registered on the pad)")
    ax = axes[1]
    under = [r for r in sed if float(r["z_mm"]) > -6.0]  # the pad side of the Merkel layer
    shown = [r for r in delivered if float(r["z_mm"]) > -6.0] if delivered else []
    # With the display's SED beside it, one scale for both: a display that delivers less looks darker.
    top = max([1e-9] + col(under, "sed_Pa") + col(shown, "sed_Pa"))
    levels = [top * i / 20 for i in range(21)] if shown else 20
    panels = [(axes[1], under, "Merkel-layer SED at peak" + (" (target)" if delivered else ""))]
    if delivered:
        panels.append((axes[2], shown, "SED the display produces (full FE)"))
    for ax, rows, title in panels:
        if rows:
            values = [min(max(v, 0), top) for v in col(rows, "sed_Pa")] if shown else col(rows, "sed_Pa")
            s = ax.tricontourf(col(rows, "x_mm"), col(rows, "y_mm"), values, levels=levels, cmap="inferno")
            fig.colorbar(s, ax=ax, label="SED [Pa]")
        ax.set_title(title)
    ax = axes[-1]
    if cmd:
        values = col(cmd, "value")
        # Fixed scale 0..ceiling, so a weak frame looks weak; saturated actuators get a red ring.
        s = ax.scatter(col(cmd, "x_mm"), col(cmd, "y_mm"), c=values, s=500, marker="o", cmap="Blues",
                       edgecolors="k", vmin=0, vmax=ceiling or None)
        fig.colorbar(s, ax=ax, label="command [%s]" % unit)
        if ceiling:
            sat = [i for i, v in enumerate(values) if v >= ceiling * (1 - 1e-6)]
            if sat:
                ax.scatter([col(cmd, "x_mm")[i] for i in sat], [col(cmd, "y_mm")[i] for i in sat], s=700,
                           facecolors="none", edgecolors="tab:red", linewidths=2)
                ax.text(0.02, 0.02, "%d/%d at the %g %s ceiling" % (len(sat), len(values), ceiling, unit),
                        transform=ax.transAxes, fontsize=8, color="tab:red")
    ax.set_title("display command at peak")
    for ax in axes:
        ax.set_xlabel("x [mm] (lateral)")
        ax.set_ylabel("y [mm] (toward tip)")
        ax.set_aspect("equal", adjustable="datalim")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "bridge_peak.png"), dpi=120)
    plt.close(fig)
    return 0


if __name__ == "__main__":
    sys.exit(main())
