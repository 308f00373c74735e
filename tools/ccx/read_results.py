#!/usr/bin/env python3
"""Reads a CalculiX press run (press.dat written by export_deck.py's deck) and writes the
files `sedbridge press` writes:

  force_displacement.csv  step,displacement_mm,force_N,contact_area_mm2
  merkel_sed.csv          vertex,x_mm,y_mm,z_mm,sed_Pa   (Gmsh node tag, REST position in
                          the pad frame, at the increment whose force is closest to 1.0 N)
  sed_path.csv            x_mm,sed_Pa,sed_normalized  (along x at y = 2 mm, pad-facing sheet)

usage: read_results.py --model B --run DIR/ccx [--out DIR] [--target-force 1.0 | --at-depth-mm D]
                       [--merkel-side both|epidermis|dermis]

Definitions, all as src/scene (press_experiment.cpp, merkel_layer.cpp):
  force      = -RF_z summed over the plane's nodes (the plane is pushed along -z_pad);
  area       = sum over skin slave nodes in contact (current gap to the plane <= the
               contact clearance CONTACT_GAP_MM) of one third of the rest area of their
               adjacent skin triangles;
  element SED= mean of ENER over the element's integration points [MPa -> Pa];
  vertex SED = mean of the SED of ALL soft elements that contain the Merkel vertex
               (--merkel-side epidermis|dermis: only that side's elements, a one-sided
               value at the interface, where the stiffness and the SED jump);
  path       = SED interpolated linearly (barycentric, rest pad-frame x, y) on the
               Merkel triangles facing the pad (normal . z_pad > 0), the sheet with the
               largest z where several overlap; x from -8 to 8 mm every 0.1 mm; normalized
               by the map's maximum (max over all Merkel vertices).
"""
import argparse
import json
import math
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fingertip  # noqa: E402

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
CONTACT_GAP_MM = 1.0e-3   # node counted in contact when its gap to the plane is below this
TARGET_FORCE_N = 1.0
PATH_Y_MM, PATH_HALF_WIDTH_MM, PATH_STEP_MM = 2.0, 8.0, 0.1

_HEADER = re.compile(r"^\s*(.+?)\s+for set\s+(\S+)\s+and time\s+(\S+)")


class ResultError(Exception):
    pass


def parse_dat(path, on_increment=None):
    """Yields per time: dict(time, force=(fx,fy,fz), u={node: (ux,uy,uz)}, ener={elem: [..]}).
    Streams the file (the .dat of a C3D10 model A run is ~100 MB)."""
    incs = []
    cur = None
    kind = None
    with open(path) as f:
        for line in f:
            m = _HEADER.match(line)
            if m:
                what, _, t = m.group(1), m.group(2), float(m.group(3))
                if cur is None or abs(cur["time"] - t) > 1e-12:
                    if cur is not None and on_increment:
                        on_increment(cur)
                    cur = dict(time=t, force=None, u={}, ener={})
                    incs.append(cur)
                if what.startswith("total force"):
                    kind = "force"
                elif what.startswith("displacements"):
                    kind = "u"
                elif "energy density" in what:
                    kind = "ener"
                else:
                    kind = None
                continue
            parts = line.split()
            if not parts or cur is None or kind is None:
                continue
            try:
                if kind == "force":
                    cur["force"] = tuple(float(v) for v in parts[:3])
                elif kind == "u":
                    cur["u"][int(parts[0])] = (float(parts[1]), float(parts[2]), float(parts[3]))
                elif kind == "ener":
                    cur["ener"].setdefault(int(parts[0]), []).append(float(parts[2]))
            except (ValueError, IndexError):
                kind = None
    if cur is not None and on_increment:
        on_increment(cur)
    return incs


class MerkelMap:
    """Merkel vertices, their adjacent elements, rest pad positions and pad-facing triangles."""

    def __init__(self, model, side=None):
        """side: None (every soft element at a vertex) or a tissue name ("epidermis",
        "dermis"): only that side of the interface."""
        self.pad = model.pad_positions()
        self.vertices = model.merkel_nodes()
        vset = set(self.vertices)
        self.adjacent = {v: [] for v in self.vertices}
        for etag, tissue, n in model.soft_tets:
            if side is not None and tissue != side:
                continue
            for v in n:
                if v in vset:
                    self.adjacent[v].append(etag)
        if side is not None and not all(self.adjacent.values()):
            raise ResultError(f"model {model.name}: some Merkel vertices have no {side} element")
        self.pad_triangles = []
        for a, b, c in model.merkel:
            pa, pb, pc = self.pad[a], self.pad[b], self.pad[c]
            normal = fingertip.cross(fingertip.sub(pb, pa), fingertip.sub(pc, pa))
            if normal[2] > 0:
                self.pad_triangles.append((a, b, c))

    def vertex_sed(self, element_sed):
        out = {}
        for v in self.vertices:
            vals = [element_sed[e] for e in self.adjacent[v] if e in element_sed]
            if len(vals) != len(self.adjacent[v]):
                raise ResultError(f"ENER missing for elements around Merkel vertex {v}")
            out[v] = sum(vals) / len(vals) if vals else 0.0
        return out

    def sample_path(self, sed, y=PATH_Y_MM, x_min=-PATH_HALF_WIDTH_MM, x_max=PATH_HALF_WIDTH_MM,
                    step=PATH_STEP_MM):
        out = []
        count = int(math.floor((x_max - x_min) / step + 1e-9)) + 1
        for s in range(count):
            px = x_min + s * step
            best_z, value = -math.inf, 0.0
            for t in self.pad_triangles:
                a, b, c = (self.pad[i] for i in t)
                det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])
                if abs(det) < 1e-12:
                    continue
                l1 = ((px - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (y - a[1])) / det
                l2 = ((b[0] - a[0]) * (y - a[1]) - (px - a[0]) * (b[1] - a[1])) / det
                l0 = 1 - l1 - l2
                if min(l0, l1, l2) < -1e-9:
                    continue
                z = l0 * a[2] + l1 * b[2] + l2 * c[2]
                if z > best_z:
                    best_z = z
                    value = l0 * sed[t[0]] + l1 * sed[t[1]] + l2 * sed[t[2]]
            if math.isfinite(best_z):
                out.append((px, value))
        return out


def read_run(model, run_dir, target_force_n=TARGET_FORCE_N, at_depth_mm=None, merkel_side=None):
    """Returns dict(steps=[(step, disp_mm, force_N, area_mm2)], selected, vertex_sed, path).
    The map is taken at the increment closest to target_force_n, or to at_depth_mm if given
    (equal indentation: for comparing runs whose forces differ, or a run still going)."""
    dat = os.path.join(run_dir, "press.dat")
    meta_path = os.path.join(run_dir, "deck.json")
    if not os.path.exists(dat):
        raise ResultError(f"{dat} does not exist (did ccx run?)")
    meta = {}
    if os.path.exists(meta_path):
        with open(meta_path) as f:
            meta = json.load(f)
    depth = float(meta.get("depth_mm", 2.0))
    n_inc = int(meta.get("increments", 50))
    pad = model.pad_positions()
    skin_area = fingertip.vertex_area_shares(model.skin, pad)
    mm = MerkelMap(model, merkel_side)
    steps, element_sed_by_step = [], []

    def on_inc(inc):
        if inc["force"] is None:
            raise ResultError(f"{dat}: no plane force at time {inc['time']}")
        t = inc["time"]  # printed with 7 digits: snap to the increment grid when on it
        if abs(t * n_inc - round(t * n_inc)) < 1e-4:
            t = round(t * n_inc) / n_inc
        d = t * depth
        plane_z = -d
        area = 0.0
        for n, u in inc["u"].items():
            if n in skin_area and n in pad:
                gap = plane_z - (pad[n][2] + u[2])
                if gap <= CONTACT_GAP_MM:
                    area += skin_area[n]
        esed = {e: 1e6 * sum(v) / len(v) for e, v in inc["ener"].items()}
        steps.append((len(steps) + 1, d, -inc["force"][2], area))
        element_sed_by_step.append(esed)

    parse_dat(dat, on_inc)
    if not steps:
        raise ResultError(f"{dat}: no converged increment")
    sta = os.path.join(run_dir, "press.sta")
    if os.path.exists(sta):
        with open(sta) as f:
            converged = sum(1 for line in f if re.match(r"\s*\d+\s+\d+\s+\d+\s+\d+\s", line))
        if converged != len(steps):
            raise ResultError(f"{dat} holds {len(steps)} increments but {sta} lists {converged} "
                              "converged ones (was an output FREQUENCY set?)")
    if at_depth_mm is not None:
        selected = min(range(len(steps)), key=lambda i: abs(steps[i][1] - at_depth_mm))
    else:
        selected = min(range(len(steps)), key=lambda i: abs(steps[i][2] - target_force_n))
    vsed = mm.vertex_sed(element_sed_by_step[selected])
    path = mm.sample_path(vsed)
    return dict(steps=steps, selected=selected, vertex_sed=vsed, path=path, merkel=mm,
                max_sed=max(vsed.values()) if vsed else 0.0)


def write_csvs(result, out_dir):
    os.makedirs(out_dir, exist_ok=True)
    with open(os.path.join(out_dir, "force_displacement.csv"), "w") as f:
        f.write("step,displacement_mm,force_N,contact_area_mm2\n")
        for s, d, force, area in result["steps"]:
            f.write(f"{s},{d:.8g},{force:.8g},{area:.8g}\n")
    mm = result["merkel"]
    with open(os.path.join(out_dir, "merkel_sed.csv"), "w") as f:
        f.write("vertex,x_mm,y_mm,z_mm,sed_Pa\n")
        for v in mm.vertices:
            p = mm.pad[v]
            f.write(f"{v},{p[0]:.8g},{p[1]:.8g},{p[2]:.8g},{result['vertex_sed'][v]:.8g}\n")
    mx = result["max_sed"]
    with open(os.path.join(out_dir, "sed_path.csv"), "w") as f:
        f.write("x_mm,sed_Pa,sed_normalized\n")
        for x, v in result["path"]:
            f.write(f"{x:.8g},{v:.8g},{(v / mx if mx > 0 else 0.0):.8g}\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--model", required=True)
    ap.add_argument("--run", required=True, help="directory with press.dat (and deck.json)")
    ap.add_argument("--out", default=None)
    ap.add_argument("--target-force", type=float, default=TARGET_FORCE_N,
                    help="the SED map and path are taken at the increment closest to this force [N]")
    ap.add_argument("--at-depth-mm", type=float, default=None,
                    help="take the map at the increment closest to this indentation instead [mm]")
    ap.add_argument("--merkel-side", choices=["both", "epidermis", "dermis"], default="both",
                    help="Merkel vertex SED from the elements of both sides of the interface "
                         "(as sedbridge) or of one side only")
    a = ap.parse_args()
    model = fingertip.load_model(a.model, REPO)
    r = read_run(model, a.run, a.target_force, a.at_depth_mm,
                 None if a.merkel_side == "both" else a.merkel_side)
    write_csvs(r, a.out or a.run)
    s = r["steps"][r["selected"]]
    print(f"{len(r['steps'])} increments; selected step {s[0]} (d = {s[1]:.3f} mm, F = {s[2]:.4f} N); "
          f"max Merkel SED {r['max_sed']:.4g} Pa")


if __name__ == "__main__":
    main()
