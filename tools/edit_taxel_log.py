#!/usr/bin/env python3
"""Edits one taxel's frames in a candump -l log of a one-frame-per-taxel three-axis sensor
(uskin_4x4's layout: id = id_base + taxel, x, y, z as big-endian uint16 in bytes 1-6), to
make a faulty taxel out of a healthy log (sensors/taxel_health.h is what it tests).

  stuck  the taxel reads `--load-N` normal more than the unloaded scans it repeats (from the
         first scan, or from --from-s), with their noise: a load no contact could produce
  dead   the taxel repeats its unloaded first scans (noise, no load): reads ~nothing
  frozen the taxel repeats one reading (bit-identical) from --from-s

  tools/edit_taxel_log.py config/bridge/example_press.log out/stuck5.log --taxel 5 --mode stuck
"""
import argparse
import re

LINE = re.compile(r"^\((?P<t>[0-9.]+)\) (?P<ifc>\S+) (?P<id>[0-9A-Fa-f]+)#(?P<data>[0-9A-Fa-f]*)\s*$")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("log_in")
    ap.add_argument("log_out")
    ap.add_argument("--taxel", type=int, required=True)
    ap.add_argument("--mode", choices=["stuck", "dead", "frozen"], required=True)
    ap.add_argument("--load-N", type=float, default=2.5, help="stuck: added normal load [N] (default 2.5)")
    ap.add_argument("--n-per-count", type=float, default=0.0005, help="normal axis calibration [N/count] (uskin_4x4)")
    ap.add_argument("--id-base", type=lambda s: int(s, 0), default=0x710)
    ap.add_argument("--quiet-scans", type=int, default=25, help="unloaded scans at the start to repeat (default 25)")
    ap.add_argument("--from-s", type=float, default=0.0, help="the fault starts this long after the first frame [s]")
    ap.add_argument("--until-s", type=float, default=float("inf"), help="... and ends here (recovers) [s]")
    a = ap.parse_args()

    lines = open(a.log_in).read().splitlines()
    target = a.id_base + a.taxel
    quiet = []  # the taxel's first unloaded readings (x, y, z)
    t0 = None
    for line in lines:
        m = LINE.match(line)
        if m and int(m["id"], 16) == target and len(quiet) < a.quiet_scans:
            b = bytes.fromhex(m["data"])
            quiet.append(tuple(int.from_bytes(b[1 + 2 * i:3 + 2 * i], "big") for i in range(3)))
    if not quiet:
        raise SystemExit(f"no frame of id {target:#x} in {a.log_in}")
    added = round(a.load_N / a.n_per_count)
    out, k = [], 0
    for line in lines:
        m = LINE.match(line)
        if not m:
            out.append(line)
            continue
        t = float(m["t"])
        t0 = t if t0 is None else t0
        if int(m["id"], 16) != target or not (a.from_s <= t - t0 < a.until_s):
            out.append(line)
            continue
        x, y, z = quiet[k % len(quiet)] if a.mode != "frozen" else quiet[0]
        k += 1
        if a.mode == "stuck":
            z = min(z + added, 0xFFFF)
        b = bytearray(bytes.fromhex(m["data"]))
        for i, v in enumerate((x, y, z)):
            b[1 + 2 * i:3 + 2 * i] = v.to_bytes(2, "big")
        out.append(f"({m['t']}) {m['ifc']} {m['id']}#{b.hex().upper()}")
    with open(a.log_out, "w") as f:
        f.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
