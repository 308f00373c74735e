#!/usr/bin/env python3
"""Thin rods on the leader: the SED of rods of several radii pressed at many poses and forces.

Whether the leader's fingertip model (its skin's contact points) holds a thin rod is a property
of its mesh, not of the rod: a rod thinner than the points' spacing slips between them (the
press fails) or touches them in a spot or two (its Merkel SED peaks far above a thicker rod's).
This sweep presses rods of RADII at every pose (POSITIONS x yaws every YAW_STEP degrees) and
FORCES through `sedbridge fidelity --cases` (its truth column is the rod pressed directly on the
leader, as the bridge presses every rod: at least contact/contact_object.h's
kLeaderMinRodRadius_mm) and compares each radius's peak SED with the largest radius's at the
same pose and force. Its run: docs/lab-notes/2026-11-28-bridge-fidelity-rounds.md#s16.

Usage:
  tools/leader_rod_sweep.py [--sedbridge build/sedbridge] [--radii 0.5,0.6,0.7,1.0]
                            [--forces 0.3,0.7,1.2] [--positions=-0.41:3.66,0:0,2:-2]
                            [--yaw-step 10] [--flag 1.6] [--cache-dir DIR] [--out out/leader_rod_sweep]

The presses need a carrier log (any rig press: the sweep reads only the truth columns). Writes
OUT/cases.json, OUT/fidelity/ and OUT/sweep.csv (per pose and force: each radius's peak SED,
the ratio to the largest radius's, the press status) and prints, per radius, how many presses
failed and how many peaked above FLAG times the largest radius's. Standard library only.
"""
import argparse
import csv
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from logged_run import run_logged  # noqa: E402


def number_list(text, name):
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise SystemExit(f"leader_rod_sweep: --{name}: not a comma-separated list of numbers: '{text}'")
    if not values or any(not (v > 0) for v in values):
        raise SystemExit(f"leader_rod_sweep: --{name}: needs positive numbers: '{text}'")
    return values


def positions_list(text):
    out = []
    for item in text.split(","):
        try:
            x, y = (float(v) for v in item.split(":"))
        except ValueError:
            raise SystemExit(f"leader_rod_sweep: --positions: '{item}' is not x:y in mm")
        out.append((x, y))
    return out


def sweep_cases(radii, forces, positions, yaw_step, log):
    """The cases.json entries: every position, yaw, force and radius."""
    cases = []
    yaw = 0.5 * yaw_step
    yaws = []
    while yaw < 180:
        yaws.append(round(yaw, 6))
        yaw += yaw_step
    for x, y in positions:
        for yaw in yaws:
            for force in forces:
                for radius in radii:
                    cases.append({"object": {"shape": "cylinder", "position_mm": [x, y], "radius_mm": radius,
                                             "yaw_deg": yaw}, "force_N": force, "log": log})
    return cases


def summarize(rows, radii, flag):
    """Groups fidelity.csv rows by pose and force. Returns (table rows, per-radius counts)."""
    groups = {}
    for r in rows:
        key = (float(r["x_mm"]), float(r["y_mm"]), float(r["yaw_deg"]), float(r["force_N"]))
        valid = r["truth_valid"] == "1"
        sed = float(r["truth_max_sed_Pa"]) if r["truth_max_sed_Pa"] else float("nan")
        groups.setdefault(key, {})[float(r["radius_mm"])] = (sed, valid, r["truth_press"].split(" ")[0])
    reference = max(radii)
    table, counts = [], {radius: {"failed": 0, "flagged": 0} for radius in radii}
    for key, by_radius in groups.items():
        if set(by_radius) != set(radii):
            raise SystemExit(f"leader_rod_sweep: fidelity.csv lacks radii at pose {key}")
        ref_sed, ref_valid, _ = by_radius[reference]
        row = {"x_mm": key[0], "y_mm": key[1], "yaw_deg": key[2], "force_N": key[3]}
        for radius in radii:
            sed, valid, status = by_radius[radius]
            ratio = sed / ref_sed if valid and ref_valid and ref_sed > 0 else float("nan")
            row[f"sed_Pa_R{radius:g}"] = sed
            row[f"ratio_R{radius:g}"] = ratio
            row[f"press_R{radius:g}"] = status
            counts[radius]["failed"] += not valid
            counts[radius]["flagged"] += ratio > flag
        table.append(row)
    return table, counts


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sedbridge", default="build/sedbridge")
    ap.add_argument("--radii", default="0.5,0.6,0.7,1.0")
    ap.add_argument("--forces", default="0.3,0.7,1.2")
    ap.add_argument("--positions", default="-0.41:3.66,0:0,2:-2,-3:1,1.5:2.5,-2:-3.5")
    ap.add_argument("--yaw-step", type=float, default=10.0)
    ap.add_argument("--flag", type=float, default=1.6, help="flag a peak above this times the largest radius's")
    ap.add_argument("--log", default="config/sensors/rig_uskin_4x4/press_12.log",
                    help="carrier log (any rig press; only the truth columns are read)")
    ap.add_argument("--cache-dir", help="compliance precompute cache (default: the bridge config's)")
    ap.add_argument("--out", default="out/leader_rod_sweep")
    args = ap.parse_args()

    radii = number_list(args.radii, "radii")
    forces = number_list(args.forces, "forces")
    positions = positions_list(args.positions)
    if not (args.yaw_step > 0 and args.yaw_step <= 180):
        raise SystemExit(f"leader_rod_sweep: --yaw-step must be in (0, 180]: {args.yaw_step}")
    if len(radii) < 2:
        raise SystemExit("leader_rod_sweep: --radii needs at least two radii (the largest is the reference)")
    if not os.path.isfile(args.log):
        raise SystemExit(f"leader_rod_sweep: --log: no such file: {args.log}")
    os.makedirs(args.out, exist_ok=True)
    cases = sweep_cases(radii, forces, positions, args.yaw_step, os.path.abspath(args.log))
    cases_path = os.path.join(args.out, "cases.json")
    with open(cases_path, "w") as f:
        json.dump({"cases": cases}, f, indent=1)
    print(f"leader_rod_sweep: {len(cases)} presses ({len(positions)} places x yaws every {args.yaw_step:g} deg x "
          f"{len(forces)} forces x {len(radii)} radii)", flush=True)
    fidelity_dir = os.path.join(args.out, "fidelity")
    command = [args.sedbridge, "fidelity", "--cases", cases_path, "--no-plots", "--out", fidelity_dir]
    if args.cache_dir:
        command += ["--cache-dir", args.cache_dir]
    run_logged(command, os.path.join(args.out, "fidelity.log"), "leader_rod_sweep")
    with open(os.path.join(fidelity_dir, "fidelity.csv")) as f:
        table, counts = summarize(list(csv.DictReader(f)), radii, args.flag)
    sweep_path = os.path.join(args.out, "sweep.csv")
    with open(sweep_path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(table[0].keys()))
        writer.writeheader()
        writer.writerows(table)
    print(f"{'radius [mm]':>12} {'failed':>8} {'> %g x' % args.flag:>10}   of {len(table)} poses and forces "
          f"(reference: R{max(radii):g})")
    for radius in radii:
        print(f"{radius:12g} {counts[radius]['failed']:8d} {counts[radius]['flagged']:10d}")
    print(f"wrote {sweep_path}")


if __name__ == "__main__":
    sys.exit(main())
