#!/usr/bin/env python3
"""Writes a CalculiX input deck for the paper's press experiment on a fingertip model.

usage: export_deck.py --model B [--element C3D4|C3D10] [--increments 50]
                      [--depth-mm 2.0] [--contact-slope 50] --out DIR

Deck (units mm, N, MPa; coordinates in the model's PAD FRAME, so the plane is z = 0 and
moves along -z):
  * soft tets as C3D4 or C3D10 (mid-edge nodes added here, shared between neighbours,
    numbered above the largest Gmsh node tag; corner nodes keep the Gmsh node tags and
    elements keep the Gmsh element tags); one *MATERIAL per soft group from the model YAML
    (linear *ELASTIC; with NLGEOM CalculiX makes it St Venant-Kirchhoff);
  * bone + nail rigid and fixed: every soft node attached to bone/nail is fixed in all
    DOF (C3D10: also the mid-edge nodes of edges on the bone/nail surface); the rigid tets
    are not in the deck. This differs from `sedbridge press`, which
    couples those nodes with penalty springs (k_bone = 200 N/m);
  * the plane: one stiff C3D8 block (z in [0, 1] mm, |x|, |y| <= 30 mm) whose 8 nodes are
    all prescribed: ux = uy = 0, uz ramped to -depth over the step. Its summed reaction
    force is the press force. Frictionless node-to-surface penalty contact (slave = skin
    nodes facing the pad, master = the block's bottom face), PRESSURE-OVERCLOSURE=LINEAR;
  * model A: the stratum corneum as S3 shells (C3D10: S6) on the skin triangles of the
    `stratum_corneum` group, thickness and material from the YAML;
  * *STATIC, NLGEOM, increments of 1/N with automatic cut-back allowed;
  * output to the .dat every increment: plane RF totals, U of the slave nodes (contact
    area), ENER of every element around a Merkel vertex; U to the .frd (for cgx).
"""
import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fingertip  # noqa: E402

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
# C3D10 mid-edge node order (CalculiX / Abaqus): 5:(1,2) 6:(2,3) 7:(3,1) 8:(1,4) 9:(2,4) 10:(3,4)
C3D10_EDGES = ((0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3))
SLAVE_DEPTH_MM = 4.0   # skin nodes with rest z_pad > -this can meet the plane (push 2 mm)


def _lines(values, per=8):
    out = []
    for i in range(0, len(values), per):
        out.append(", ".join(str(v) for v in values[i:i + per]) + ("," if i + per < len(values) else ""))
    return "\n".join(out)


def export(model, out_dir, element="C3D4", increments=50, depth_mm=2.0, contact_slope=50.0,
           shells=True, material_law="elastic"):
    """Writes DIR/press.inp and DIR/deck.json (what the reader needs). Returns the .inp path."""
    if element not in ("C3D4", "C3D10"):
        raise ValueError("element must be C3D4 or C3D10")
    os.makedirs(out_dir, exist_ok=True)
    pad = model.pad_positions()
    pos = dict(pad)
    max_tag = max(model.nodes)
    next_node = max_tag + 1
    mid = {}
    elements = []  # (tag, tissue, conn)
    for etag, tissue, n in model.soft_tets:
        conn = list(n)
        if element == "C3D10":
            for a, b in C3D10_EDGES:
                key = (min(n[a], n[b]), max(n[a], n[b]))
                if key not in mid:
                    mid[key] = next_node
                    pa, pb = pos[n[a]], pos[n[b]]
                    pos[next_node] = tuple(0.5 * (pa[i] + pb[i]) for i in range(3))
                    next_node += 1
                conn.append(mid[key])
        elements.append((etag, tissue, conn))
    max_elem = max(max(e[0] for e in elements), max((t[0] for t in model.rigid_tets), default=0))

    # Plane block nodes (bottom face z = 0 counterclockwise seen from +z -> face S1 normal -z).
    L = 30.0
    plane_nodes = []
    for z in (0.0, 1.0):
        for x, y in ((-L, -L), (L, -L), (L, L), (-L, L)):
            pos[next_node] = (x, y, z)
            plane_nodes.append(next_node)
            next_node += 1
    plane_elem = max_elem + 1

    fixed = list(model.attached)
    if element == "C3D10":
        # mid-edge nodes on the bone/nail surface (edges shared with a rigid tet) are fixed too
        rigid_edges = set()
        for _, _, n in model.rigid_tets:
            for a, b in C3D10_EDGES:
                rigid_edges.add((min(n[a], n[b]), max(n[a], n[b])))
        fixed += [node for key, node in mid.items() if key in rigid_edges]
    fixed = sorted(fixed)
    fixed_set = set(model.attached)
    slave = [n for n in model.skin_nodes() if pad[n][2] > -SLAVE_DEPTH_MM and n not in fixed_set]
    if element == "C3D10":
        # mid-edge nodes of skin triangles on the pad side are slaves too
        slave_set = set(slave)
        for a, b, c in model.skin:
            for u, v in ((a, b), (b, c), (c, a)):
                if u in slave_set and v in slave_set:
                    slave.append(mid[(min(u, v), max(u, v))])
        slave = sorted(set(slave))
    merkel_nodes = set(model.merkel_nodes())
    merkel_adj = sorted({e[0] for e in elements if merkel_nodes.intersection(e[2][:4])})

    shell_elems = []
    if shells and model.sc:
        stag = plane_elem + 1
        for a, b, c in model.sc:
            conn = [a, b, c]
            if element == "C3D10":
                conn += [mid[(min(u, v), max(u, v))] for u, v in ((a, b), (b, c), (c, a))]
            shell_elems.append((stag, conn))
            stag += 1

    inp = os.path.join(out_dir, "press.inp")
    w = []
    w.append("** sedbridge CalculiX reference deck (tools/ccx/export_deck.py)")
    w.append(f"** model {model.name}, {element}, plane pushed {depth_mm} mm along -z_pad in {increments} increments")
    w.append("** units: mm, N, MPa; coordinates: pad frame (x lateral, y to the tip, z outward pad normal)")
    w.append("*HEADING")
    w.append(f"sedbridge press reference, model {model.name}, {element}")
    w.append("*NODE, NSET=NALL")
    for tag in sorted(pos):
        p = pos[tag]
        w.append(f"{tag}, {p[0]:.12g}, {p[1]:.12g}, {p[2]:.12g}")
    tissues = sorted({e[1] for e in elements})
    for tissue in tissues:
        w.append(f"*ELEMENT, TYPE={element}, ELSET={tissue.upper()}")
        for etag, t, conn in elements:
            if t == tissue:
                w.append(f"{etag}, " + ", ".join(str(c) for c in conn))
    w.append("*ELEMENT, TYPE=C3D8, ELSET=PLANE")
    w.append(f"{plane_elem}, " + ", ".join(str(c) for c in plane_nodes))
    if shell_elems:
        stype = "S6" if element == "C3D10" else "S3"
        w.append(f"*ELEMENT, TYPE={stype}, ELSET=STRATUM_CORNEUM")
        for stag, conn in shell_elems:
            w.append(f"{stag}, " + ", ".join(str(c) for c in conn))
    w.append("*NSET, NSET=FIXED")
    w.append(_lines(fixed))
    w.append("*NSET, NSET=PLANEN")
    w.append(_lines(plane_nodes))
    w.append("*NSET, NSET=SLAVEN")
    w.append(_lines(slave))
    w.append("*ELSET, ELSET=MERKELADJ")
    w.append(_lines(merkel_adj))
    for tissue in tissues:
        mat = model.materials[tissue]
        w.append(f"*MATERIAL, NAME=M_{tissue.upper()}")
        _write_law(w, mat, material_law)
        w.append(f"*SOLID SECTION, ELSET={tissue.upper()}, MATERIAL=M_{tissue.upper()}")
    w.append("*MATERIAL, NAME=M_PLANE")
    w.append("*ELASTIC")
    w.append("1.0e5, 0.3")
    w.append("*SOLID SECTION, ELSET=PLANE, MATERIAL=M_PLANE")
    if shell_elems:
        w.append("*MATERIAL, NAME=M_STRATUM_CORNEUM")
        _write_law(w, model.sc_material, material_law)
        # Shell normals follow the skin triangles (outward); OFFSET=-0.5 puts the shell
        # outside the epidermis (its inner face on the skin), like a coat on the skin.
        w.append("*SHELL SECTION, ELSET=STRATUM_CORNEUM, MATERIAL=M_STRATUM_CORNEUM, OFFSET=-0.5")
        w.append(f"{model.sc_thickness_mm:.6g}")
    w.append("*SURFACE, NAME=SLAVE, TYPE=NODE")
    w.append("SLAVEN")
    w.append("*SURFACE, NAME=MASTER, TYPE=ELEMENT")
    w.append(f"{plane_elem}, S1")
    w.append("*SURFACE INTERACTION, NAME=SI")
    w.append("*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR")
    w.append(f"{contact_slope:.6g}, 1.0e-6, 0.001")
    w.append("*CONTACT PAIR, INTERACTION=SI, TYPE=NODE TO SURFACE")
    w.append("SLAVE, MASTER")
    w.append("*BOUNDARY")
    w.append("FIXED, 1, 3")
    w.append("PLANEN, 1, 2")
    w.append("*STEP, NLGEOM, INC=10000")
    w.append("*STATIC")
    dt = 1.0 / increments
    w.append(f"{dt:.8g}, 1.0, {dt * 1e-3:.8g}, {dt:.8g}")
    w.append("*BOUNDARY")
    w.append(f"PLANEN, 3, 3, {-depth_mm:.8g}")
    w.append("*NODE PRINT, NSET=PLANEN, TOTALS=ONLY")
    w.append("RF")
    w.append("*NODE PRINT, NSET=SLAVEN")
    w.append("U")
    w.append("*EL PRINT, ELSET=MERKELADJ")
    w.append("ENER")
    # .frd for viewing in cgx: displacements only (stress fields of model A would be ~1 GB).
    # No FREQUENCY parameter: in ccx it applies to the .dat prints as well.
    w.append("*NODE FILE")
    w.append("U")
    w.append("*END STEP")
    with open(inp, "w") as f:
        f.write("\n".join(w) + "\n")
    meta = dict(model=model.name, element=element, increments=increments, depth_mm=depth_mm,
                contact_slope_MPa_per_mm=contact_slope, shells=bool(shell_elems),
                material_law=material_law,
                slave_nodes=len(slave), fixed_nodes=len(fixed), soft_tets=len(elements),
                nodes=len(pos), merkel_adjacent_elements=len(merkel_adj))
    with open(os.path.join(out_dir, "deck.json"), "w") as f:
        json.dump(meta, f, indent=1)
    return inp


def _write_law(w, mat, law):
    E, nu = mat["E_MPa"], mat["nu"]
    if law == "elastic":
        w.append("*ELASTIC")
        w.append(f"{E:.8g}, {nu:.8g}")
    elif law == "neohooke":
        # Same small-strain stiffness: C10 = mu/2, D1 = 2/K.
        mu = E / (2 * (1 + nu))
        K = E / (3 * (1 - 2 * nu))
        w.append("*HYPERELASTIC, NEO HOOKE")
        w.append(f"{mu / 2:.8g}, {2 / K:.8g}")
    else:
        raise ValueError("material law: elastic | neohooke")


def add_deck_arguments(ap):
    """The deck's options, shared with run_reference.py."""
    ap.add_argument("--model", required=True)
    ap.add_argument("--element", default="C3D4", choices=("C3D4", "C3D10"))
    ap.add_argument("--increments", type=int, default=50)
    ap.add_argument("--depth-mm", type=float, default=2.0)
    ap.add_argument("--contact-slope", type=float, default=50.0, help="penalty slope [MPa/mm]")
    ap.add_argument("--no-shells", action="store_true", help="model A without its stratum corneum shell")
    ap.add_argument("--material-law", default="elastic", choices=("elastic", "neohooke"))


def export_from_args(model, out_dir, a):
    """export() with the options of add_deck_arguments."""
    return export(model, out_dir, a.element, a.increments, a.depth_mm, a.contact_slope,
                  not a.no_shells, a.material_law)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_deck_arguments(ap)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    print(export_from_args(fingertip.load_model(a.model, REPO), a.out, a))


if __name__ == "__main__":
    main()
