#!/usr/bin/env python3
"""CalculiX end-to-end checks of tools/ccx (needs `ccx`; exits 77 = skipped without it).

1. Uniaxial block: a unit cube of 6 tets (C3D4, and C3D10 with the exporter's mid-edge
   node numbering), rollers on three faces, 0.1 % compression, linear. The .dat reader's
   element SED must equal the analytic sigma*eps/2 = E eps^2 / 2 (within 1e-6).
2. A failing deck gives ccx's *ERROR text and ok = False (never a silent success).
3. B_coarse press, 3 increments of 0.2 mm through run_reference.py: force > 0 and
   growing, contact area growing, the Merkel map covers every Merkel vertex, the path is
   normalized by the map maximum.
4. The elastic layer under a disk load (layer_reference.py): a thin layer's centre
   deflection near the confined columns', the one the C++ test records for h/c = 1.

usage: test_ccx_press.py [--work DIR]
"""
import argparse
import csv
import os
import shutil
import subprocess
import sys
import tempfile

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
sys.path.insert(0, os.path.join(REPO, "tools", "ccx"))
import export_deck  # noqa: E402
import fingertip  # noqa: E402
import read_results  # noqa: E402
import run_reference  # noqa: E402
import layer_reference  # noqa: E402

FAILURES = []


def check(cond, what):
    print(("ok    " if cond else "FAIL  ") + what, flush=True)
    if not cond:
        FAILURES.append(what)


CUBE = {1: (0, 0, 0), 2: (1, 0, 0), 3: (1, 1, 0), 4: (0, 1, 0),
        5: (0, 0, 1), 6: (1, 0, 1), 7: (1, 1, 1), 8: (0, 1, 1)}
CUBE_TETS = [(1, 2, 3, 7), (1, 3, 4, 7), (1, 4, 8, 7), (1, 8, 5, 7), (1, 5, 6, 7), (1, 6, 2, 7)]


def uniaxial_block(work, element):
    E, nu, eps = 0.1, 0.3, 1e-3
    pos = dict(CUBE)
    tets = []
    mid, nxt = {}, 100
    for n in CUBE_TETS:
        n = list(n)
        if fingertip.signed_volume(*(pos[t] for t in n)) < 0:
            n = [n[0], n[2], n[1], n[3]]
        conn = list(n)
        if element == "C3D10":
            for a, b in export_deck.C3D10_EDGES:
                key = (min(n[a], n[b]), max(n[a], n[b]))
                if key not in mid:
                    mid[key] = nxt
                    pos[nxt] = tuple(0.5 * (pos[n[a]][i] + pos[n[b]][i]) for i in range(3))
                    nxt += 1
                conn.append(mid[key])
        tets.append(conn)
    d = os.path.join(work, "block_" + element)
    os.makedirs(d, exist_ok=True)
    on = lambda axis, v: [t for t, p in pos.items() if abs(p[axis] - v) < 1e-12]  # noqa: E731
    w = ["*NODE, NSET=NALL"] + [f"{t}, {p[0]}, {p[1]}, {p[2]}" for t, p in sorted(pos.items())]
    w.append(f"*ELEMENT, TYPE={element}, ELSET=EALL")
    w += [f"{k + 1}, " + ", ".join(map(str, c)) for k, c in enumerate(tets)]
    w += ["*MATERIAL, NAME=M", "*ELASTIC", f"{E}, {nu}", "*SOLID SECTION, ELSET=EALL, MATERIAL=M",
          "*BOUNDARY"]
    w += [f"{t}, 1, 1" for t in on(0, 0.0)] + [f"{t}, 2, 2" for t in on(1, 0.0)] + [f"{t}, 3, 3" for t in on(2, 0.0)]
    w += ["*STEP", "*STATIC", "*BOUNDARY"] + [f"{t}, 3, 3, {-eps}" for t in on(2, 1.0)]
    w += ["*EL PRINT, ELSET=EALL", "ENER", "*END STEP"]
    with open(os.path.join(d, "press.inp"), "w") as f:
        f.write("\n".join(w) + "\n")
    ok, t, errors, _ = run_reference.run_ccx(d, 1, os.path.join(d, "ccx.log"), quiet=True)
    check(ok, f"uniaxial block {element}: ccx ran ({'; '.join(errors)})")
    incs = read_results.parse_dat(os.path.join(d, "press.dat"))
    expected = 0.5 * E * eps * eps * 1e6  # Pa
    sed = [1e6 * sum(v) / len(v) for v in incs[-1]["ener"].values()]
    check(len(sed) == 6 and all(abs(s - expected) <= 1e-6 * expected for s in sed),
          f"uniaxial block {element}: element SED {min(sed):.6g}..{max(sed):.6g} Pa = E eps^2/2 = {expected:.6g} Pa")


def failing_deck(work):
    d = os.path.join(work, "broken")
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "press.inp"), "w") as f:
        f.write("*NODE\n1, 0, 0, 0\n*STEP\n*STATIC\n*BOUNDARY\nNOSUCHSET, 1, 1, 0.0\n*END STEP\n")
    ok, _, errors, _ = run_reference.run_ccx(d, 1, os.path.join(d, "ccx.log"), quiet=True)
    check(not ok and any("ERROR" in e for e in errors), f"broken deck reported: {errors[:1]}")


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def b_coarse_press(work):
    out = os.path.join(work, "B_coarse")
    rc = subprocess.call([sys.executable, os.path.join(REPO, "tools", "ccx", "run_reference.py"),
                          "--model", "B_coarse", "--increments", "3", "--depth-mm", "0.6", "--threads", "1",
                          "--no-plots", "--out", out])
    check(rc == 0, "run_reference.py B_coarse, 3 increments: exit 0")
    if rc != 0:
        return
    fd = read(os.path.join(out, "force_displacement.csv"))
    d = [float(r["displacement_mm"]) for r in fd]
    force = [float(r["force_N"]) for r in fd]
    area = [float(r["contact_area_mm2"]) for r in fd]
    check(len(fd) == 3 and all(abs(a - b) < 1e-6 for a, b in zip(d, (0.2, 0.4, 0.6))), f"displacements {d}")
    check(force[0] > 0 and force[0] < force[1] < force[2], f"force > 0 and growing: {force}")
    check(area[0] > 0 and area[0] <= area[1] <= area[2], f"contact area growing: {area}")
    m = fingertip.load_model("B_coarse", REPO)
    sed = read(os.path.join(out, "merkel_sed.csv"))
    check(sorted(int(r["vertex"]) for r in sed) == m.merkel_nodes(), "merkel_sed.csv: every Merkel vertex (Gmsh tags)")
    mx = max(float(r["sed_Pa"]) for r in sed)
    check(mx > 0 and all(float(r["sed_Pa"]) >= 0 for r in sed), f"Merkel SED >= 0, max {mx:.1f} Pa")
    path = read(os.path.join(out, "sed_path.csv"))
    norm = [float(r["sed_normalized"]) for r in path]
    check(len(path) > 50 and max(norm) <= 1 + 1e-6 and max(norm) > 0.3,
          f"sed_path.csv: {len(path)} samples, max normalized {max(norm):.3f}")
    # Map at equal indentation: the increment closest to 0.25 mm is the first (0.2 mm),
    # whose SED is below the last increment's.
    first = read_results.read_run(m, os.path.join(out, "ccx"), at_depth_mm=0.25)
    check(first["selected"] == 0, f"--at-depth-mm 0.25 selects increment 1, got {first['selected'] + 1}")
    check(0 < first["max_sed"] < mx, f"SED at 0.2 mm ({first['max_sed']:.1f} Pa) below the 0.6 mm one ({mx:.1f} Pa)")


def elastic_layer(work):
    # ElasticPadContact.LayerMatchesCalculixUnderADiskLoad records 0.92450 for h/c = 1, nu 0.2.
    w = layer_reference.run(1.0, 0.2, os.path.join(work, "layer_h1"))
    check(abs(w - 0.92450) < 2e-4, f"layer h/c 1, nu 0.2: centre deflection {w:.5f} p c / E* (recorded 0.92450)")
    thin = layer_reference.run(0.5, 0.2, os.path.join(work, "layer_h0.5"))
    columns = 0.5 * (1 - 2 * 0.2) / (1 - 0.2) ** 2  # confined columns, w E* / (p c)
    check(columns < thin < 1.05 * columns, f"thin layer {thin:.5f} just above the confined columns' {columns:.5f}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--work", default=None)
    a = ap.parse_args()
    if not shutil.which("ccx"):
        print("SKIPPED: `ccx` (CalculiX, Debian package calculix-ccx) is not installed")
        return 77
    work = a.work or tempfile.mkdtemp(prefix="ccx_test_")
    if os.path.exists(work):
        shutil.rmtree(work)
    os.makedirs(work)
    uniaxial_block(work, "C3D4")
    uniaxial_block(work, "C3D10")
    failing_deck(work)
    b_coarse_press(work)
    elastic_layer(work)
    print(f"{len(FAILURES)} failure(s)")
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main())
