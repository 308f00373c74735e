#!/usr/bin/env python3
"""CalculiX reference for the simulated pad's elastic layer (sensors/simulated/elastic_pad_contact.h).

usage: layer_reference.py [--out DIR] [--cases H/C:NU,...]

An elastomer layer of thickness h bonded to a rigid base, loaded by a uniform pressure p on
a disk of radius c at its free surface: axisymmetric quadratic elements (CAX8), graded
towards the load, out to 40 h. Prints, per case, the surface deflection at the centre in
units of p c / E* (E* = E / (1 - nu^2)): the half-space's is exactly 2 (Johnson, Contact
Mechanics §3.4), a thin layer's tends to (h / c) (1 - 2 nu) / (1 - nu)^2 (confined columns).
tests/sensors/elastic_pad_contact_test.cpp checks the layer's Hankel-transform influence
against the numbers this prints.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys


def graded(x0, x1, n, ratio):
    """n intervals from x0 to x1, each `ratio` times the last."""
    if abs(ratio - 1) < 1e-12:
        return [x0 + (x1 - x0) * i / n for i in range(n + 1)]
    w = (x1 - x0) * (ratio - 1) / (ratio ** n - 1)
    xs, x = [x0], x0
    for i in range(n):
        x += w * ratio ** i
        xs.append(x)
    xs[-1] = x1
    return xs


def deck(h, nu, refine=1, c=1.0, e=1.0, p=1e-3):
    # Radial corners: uniform to c, then each about 8 % wider than the last out to 40 h (or
    # 40 c); through the thickness uniform, graded towards the surface for thick layers.
    r_out = 40 * max(h, c)
    n_out = 1
    while c * 0.05 / refine * (1.08 ** n_out - 1) / 0.08 < r_out - c:
        n_out += 1
    rs = graded(0, c, 20 * refine, 1.0) + graded(c, r_out, n_out, 1.08 ** (1.0 / 1))[1:]
    if h <= 2 * c:
        zs = graded(0, h, int(round(16 * refine * max(h / c, 0.5))), 1.0)  # base z = 0, surface z = h
    else:
        n_z = 1
        while c * 0.05 / refine * (1.08 ** n_z - 1) / 0.08 < h:
            n_z += 1
        zs = [h - z for z in reversed(graded(0, h, n_z, 1.08))]
    nr, nz = len(rs) - 1, len(zs) - 1
    def fine(cs):  # corners plus midpoints
        out = []
        for i in range(len(cs) - 1):
            out += [cs[i], 0.5 * (cs[i] + cs[i + 1])]
        return out + [cs[-1]]
    fr, fz = fine(rs), fine(zs)
    nid = lambda i, j: j * len(fr) + i + 1
    lines = ["*HEADING", "elastic layer on a rigid base, disk load", "*NODE"]
    for j, z in enumerate(fz):
        for i, r in enumerate(fr):
            if i % 2 and j % 2:
                continue  # CAX8 has no centre node
            lines.append("%d, %.10g, %.10g" % (nid(i, j), r, z))
    lines.append("*ELEMENT, TYPE=CAX8, ELSET=LAYER")
    eid, loaded = 0, []
    for J in range(nz):
        for I in range(nr):
            eid += 1
            i, j = 2 * I, 2 * J
            n = [nid(i, j), nid(i + 2, j), nid(i + 2, j + 2), nid(i, j + 2),
                 nid(i + 1, j), nid(i + 2, j + 1), nid(i + 1, j + 2), nid(i, j + 1)]
            lines.append("%d, %s" % (eid, ", ".join(map(str, n))))
            if J == nz - 1 and rs[I + 1] <= c + 1e-12:
                loaded.append(eid)
    lines.append("*NSET, NSET=BASE")
    lines += ["%d," % nid(i, 0) for i in range(len(fr))]
    lines.append("*NSET, NSET=AXIS")
    lines += ["%d," % nid(0, j) for j in range(len(fz))]
    lines.append("*NSET, NSET=CENTRE")
    lines.append("%d," % nid(0, len(fz) - 1))
    lines += ["*MATERIAL, NAME=ELASTOMER", "*ELASTIC", "%g, %g" % (e, nu),
              "*SOLID SECTION, ELSET=LAYER, MATERIAL=ELASTOMER",
              "*BOUNDARY", "BASE, 1, 2", "AXIS, 1, 1",
              "*STEP", "*STATIC", "*DLOAD"]
    lines += ["%d, P3, %g" % (k, p) for k in loaded]
    lines += ["*NODE PRINT, NSET=CENTRE", "U", "*END STEP"]
    return "\n".join(lines) + "\n"


def run(h, nu, out_dir, refine=1):
    os.makedirs(out_dir, exist_ok=True)
    with open(os.path.join(out_dir, "layer.inp"), "w") as f:
        f.write(deck(h, nu, refine))
    r = subprocess.run(["ccx", "-i", "layer"], cwd=out_dir, capture_output=True, text=True)
    dat = os.path.join(out_dir, "layer.dat")
    if r.returncode != 0 or not os.path.exists(dat):
        sys.exit("layer_reference: ccx failed:\n" + r.stdout[-2000:] + r.stderr[-2000:])
    nums = re.findall(r"^\s*\d+\s+(\S+)\s+(\S+)", open(dat).read(), re.M)
    w = -float(nums[-1][1])  # U2 (axial) of the centre node, pressed down
    e_star = 1.0 / (1 - nu * nu)
    return w * e_star / (1e-3 * 1.0)  # w E* / (p c)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[2])
    ap.add_argument("--out", default="out/ccx_layer")
    ap.add_argument("--cases", default="0.5:0.2,1:0.2,2:0.2,4:0.2,1:0.45,2:0.45,100:0.2")
    ap.add_argument("--refine", type=int, default=1, help="mesh refinement factor (convergence check)")
    a = ap.parse_args()
    if not shutil.which("ccx"):
        sys.exit("layer_reference: `ccx` not found (Debian package calculix-ccx)")
    print("h/c     nu    centre deflection w E*/(p c)")
    for case in a.cases.split(","):
        h, nu = (float(v) for v in case.split(":"))
        v = run(h, nu, os.path.join(a.out, "h%g_nu%g" % (h, nu)), a.refine)
        print("%-7g %-5g %.5f" % (h, nu, v))


if __name__ == "__main__":
    main()
