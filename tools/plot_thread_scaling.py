#!/usr/bin/env python3
"""Speed-up against team size, from tools/thread_scaling.sh's CSV.

usage: plot_thread_scaling.py CSV [--chosen CSV2] [--out PNG] [--title TEXT]

One line per case (section, model, step): the median step time of team 1 over that of each
team (1, 2, 4, 8, 16 threads), so above 1 is faster; a star marks the step's own choice
(team 0) at the team it kept, at its own speed-up. The paper's press is drawn from its wall
times. Left panel: the quiet machine (sections steps, traction, press); right panel: with
busy loops on half the cores (section load), when the CSV has it. --chosen takes the stars
from another run's CSV instead (each star's speed-up over that run's own one-thread step),
e.g. a later build measured with THREADS="1 0".
"""
import argparse
import csv
import os
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load(path):
    groups = defaultdict(dict)  # (section, model, case without the team) -> team -> row
    for row in csv.DictReader(open(path)):
        case = row["case"]
        if row["section"] != "press":
            case = case.rsplit("/", 1)[0]
        case = case.replace("ContactPressStep/backward_euler/corotational/", "contact ")
        case = case.replace("TractionStep/backward_euler/corotational/", "traction ")
        case = case.replace("press paper_press.yaml (wall s)", "paper's press")
        try:
            row["median_ms"] = float(row["median_ms"])
        except ValueError:
            continue
        groups[(row["section"], row["model"], case)][int(row["team"])] = row
    return groups


def draw(ax, groups, sections, title, chosen_groups=None):
    teams_seen = set()
    for (section, model, case), by_team in sorted(groups.items()):
        if section not in sections or 1 not in by_team:
            continue
        base = by_team[1]["median_ms"]
        teams = sorted(t for t in by_team if t > 0)
        teams_seen.update(teams)
        line, = ax.plot(teams, [base / by_team[t]["median_ms"] for t in teams], marker="o",
                        label=f"{model} {case}")
        star_source = by_team if chosen_groups is None else chosen_groups.get((section, model, case), {})
        chosen = star_source.get(0)
        if chosen and 1 in star_source and chosen["threads"] not in ("", "0", "0.0"):
            ax.plot([float(chosen["threads"])], [star_source[1]["median_ms"] / chosen["median_ms"]], marker="*",
                    markersize=14, color=line.get_color(), markeredgecolor="black", linestyle="none")
    ax.axhline(1.0, color="grey", linewidth=0.8, linestyle="--")
    ax.set_xscale("log", base=2)
    if teams_seen:
        ax.set_xticks(sorted(teams_seen))
        ax.set_xticklabels([str(t) for t in sorted(teams_seen)])
    ax.set_xlabel("OpenMP threads (team)")
    ax.set_ylabel("speed-up over 1 thread (median step)")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("csv")
    parser.add_argument("--chosen", default=None, help="CSV of another run whose team-0 rows give the stars")
    parser.add_argument("--out", default=None, help="PNG to write (default: beside the CSV)")
    parser.add_argument("--title", default="", help="figure title (the machine, the date)")
    args = parser.parse_args()
    groups = load(args.csv)
    chosen_groups = load(args.chosen) if args.chosen else None
    loaded = any(section == "load" for section, _, _ in groups)
    fig, axes = plt.subplots(1, 2 if loaded else 1, figsize=(13 if loaded else 7, 5), squeeze=False)
    draw(axes[0][0], groups, {"steps", "traction", "press"}, "quiet", chosen_groups)
    if loaded:
        draw(axes[0][1], groups, {"load"}, "busy loops on half the cores", chosen_groups)
    fig.suptitle(args.title or "thread scaling (stars: the step's own choice)")
    fig.tight_layout()
    out = args.out or os.path.join(os.path.dirname(os.path.abspath(args.csv)), "thread_scaling.png")
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
