#!/usr/bin/python3
"""Where the reconstructed contact holds, by peak force and by object: a summary of one or
more `sedbridge fidelity --out DIR` runs (typically random sets of several seeds).

Usage: fidelity_envelope.py [--plot PNG] DIR [DIR ...]

Reads DIR/fidelity.csv of each run and prints, as Markdown tables (docs/bridge-fidelity.md):
  - the scored presses by the true peak force [N] (bands 0.15, 0.3, 0.6, 1, 1.5, 2 N), each
    with how many are within all three targets (peak SED ratio 0.8-1.25, relative L2 <= 0.25,
    peak offset <= 1 mm), within them by the peak region instead of the argmax, and within the
    peak ratio and L2 alone;
  - the same by object (sphere, rod, flat, stroke, other);
  - the presses without a truth (their leader press's status: patch_edge, max_depth, ...);
  - every scored press outside the peak-ratio or L2 target, with what was reconstructed.
With --plot (needs matplotlib; Debian: python3-matplotlib): the reconstructed contact's peak
SED ratio and relative L2 error against the true peak force, one marker per object, the
target bands shaded, presses outside all three targets ringed.

Exits 2 on a folder without fidelity.csv or a CSV without the benchmark's columns.
"""
import argparse
import csv
import os
import sys

BANDS_N = [0.0, 0.15, 0.3, 0.6, 1.0, 1.5, 2.0, float("inf")]
NEEDED = ["case", "label", "shape", "force_N", "truth_valid", "truth_press", "recon_shape", "recon_radius_mm",
          "recon_peak_ratio", "recon_rel_l2", "recon_peak_offset_mm", "recon_peak_region_offset_mm",
          "recon_within_targets"]


def read_runs(dirs):
    rows = []
    for d in dirs:
        path = os.path.join(d, "fidelity.csv")
        if not os.path.isfile(path):
            print(f"fidelity_envelope: {path}: no such file (give folders written by `sedbridge fidelity --out`)",
                  file=sys.stderr)
            sys.exit(2)
        with open(path) as f:
            reader = csv.DictReader(f)
            missing = [c for c in NEEDED if c not in (reader.fieldnames or [])]
            if missing:
                print(f"fidelity_envelope: {path}:1: missing column(s) {', '.join(missing)}", file=sys.stderr)
                sys.exit(2)
            for line, r in enumerate(reader, start=2):
                try:
                    for c in ("force_N", "recon_peak_ratio", "recon_rel_l2", "recon_peak_offset_mm",
                              "recon_peak_region_offset_mm"):
                        r[c] = float(r[c])
                except ValueError as e:
                    print(f"fidelity_envelope: {path}:{line}: {e}", file=sys.stderr)
                    sys.exit(2)
                r["run"] = d
                rows.append(r)
    return rows


def ratio_and_l2(r):
    return 0.8 <= r["recon_peak_ratio"] <= 1.25 and r["recon_rel_l2"] <= 0.25


def by_region(r):
    return ratio_and_l2(r) and r["recon_peak_region_offset_mm"] <= 1.0


def within(r):
    return r["recon_within_targets"] == "1"


def kind(r):
    if "stroke" in r["case"] or "sliding" in r["case"]:
        return "stroke"
    return {"sphere": "sphere", "cylinder": "rod", "flat": "flat"}.get(r["shape"], "other")


def band_name(lo, hi):
    return f"{lo:g}-{hi:g}" if hi != float("inf") else f">= {lo:g}"


def table(title, groups):
    print(f"| {title} | scored | within all three | by peak region | peak ratio and L2 |")
    print("|---|---|---|---|---|")
    for name, rs in groups:
        if rs:
            print(f"| {name} | {len(rs)} | {sum(map(within, rs))} | {sum(map(by_region, rs))} | "
                  f"{sum(map(ratio_and_l2, rs))} |")


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    markers = {"sphere": "o", "rod": "s", "flat": "D", "stroke": "^", "other": "x"}
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4), constrained_layout=True)
    for ax, key, band, label in ((axes[0], "recon_peak_ratio", (0.8, 1.25), "peak SED ratio (bridge / truth)"),
                                 (axes[1], "recon_rel_l2", (0.0, 0.25), "relative L2 error")):
        ax.axhspan(*band, color="tab:green", alpha=0.12, label="target")
        for k, m in markers.items():
            rs = [r for r in rows if kind(r) == k]
            if not rs:
                continue
            ax.scatter([r["force_N"] for r in rs], [r[key] for r in rs], marker=m, s=22, label=k, alpha=0.8)
        out = [r for r in rows if not within(r)]
        ax.scatter([r["force_N"] for r in out], [r[key] for r in out], s=90, facecolors="none",
                   edgecolors="tab:red", linewidths=1.0, label="outside all three")
        ax.set_xscale("log")
        ax.set_xlabel("true peak force [N]")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_yscale("log")
    ticks = [0.25, 0.5, 0.8, 1.0, 1.25, 2.0, 4.0]
    lo, hi = axes[0].get_ylim()
    axes[0].set_yticks([t for t in ticks if lo <= t <= hi])
    axes[0].set_yticklabels([f"{t:g}" for t in ticks if lo <= t <= hi])
    axes[0].minorticks_off()
    axes[0].legend(fontsize=8, loc="best")
    fig.suptitle(f"reconstructed contact, {len(rows)} scored presses")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--plot", metavar="PNG", help="write the scatter plot here")
    parser.add_argument("dirs", nargs="+", metavar="DIR")
    args = parser.parse_args()
    rows = read_runs(args.dirs)
    scored = [r for r in rows if r["truth_valid"] == "1"]
    print(f"{len(rows)} presses in {len(args.dirs)} run(s), {len(scored)} scored; reconstructed contact within all "
          f"three targets {sum(map(within, scored))}, by peak region {sum(map(by_region, scored))}, peak ratio and "
          f"L2 {sum(map(ratio_and_l2, scored))}\n")
    table("true peak force [N]", [(band_name(lo, hi), [r for r in scored if lo <= r["force_N"] < hi])
                                  for lo, hi in zip(BANDS_N, BANDS_N[1:])])
    print()
    table("object", [(k, [r for r in scored if kind(r) == k]) for k in ("sphere", "rod", "flat", "stroke", "other")])
    unscored = {}
    for r in rows:
        if r["truth_valid"] != "1":
            status = r["truth_press"].split(" ")[0] or "?"
            unscored[status] = unscored.get(status, 0) + 1
    if unscored:
        print("\nwithout a truth (not scored), by the leader press's status: " +
              ", ".join(f"{k} {v}" for k, v in sorted(unscored.items(), key=lambda kv: -kv[1])))
    misses = [r for r in scored if not ratio_and_l2(r)]
    if misses:
        print("\noutside the peak-ratio or L2 target:")
        for r in sorted(misses, key=lambda r: r["force_N"]):
            print(f"  {r['label'][:44]:44s} {r['force_N']:6.3f} N  read {r['recon_shape']} R{float(r['recon_radius_mm']):.2f}"
                  f"  peak {r['recon_peak_ratio']:.2f} L2 {r['recon_rel_l2']:.2f} off {r['recon_peak_offset_mm']:.2f} mm")
    if args.plot:
        plot(scored, args.plot)
        print(f"\nwrote {args.plot}")


if __name__ == "__main__":
    main()
