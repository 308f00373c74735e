#!/usr/bin/env python3
"""Unit tests of tools/ccx (model reader, deck exporter, .dat reader, Merkel averaging and
path sampling). No CalculiX needed. Run: python3 tests/ccx/test_ccx_tools.py"""
import math
import os
import sys
import tempfile
import unittest

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
sys.path.insert(0, os.path.join(REPO, "tools", "ccx"))
import export_deck  # noqa: E402
import fingertip  # noqa: E402
import compare_paths  # noqa: E402
import read_results  # noqa: E402

_MODELS = {}


def model(name):
    if name not in _MODELS:
        _MODELS[name] = fingertip.load_model(name, REPO)
    return _MODELS[name]


class ModelReaderTest(unittest.TestCase):
    def test_yaml_materials(self):
        y = fingertip.read_simple_yaml(os.path.join(REPO, "config", "models", "B.yaml"))
        self.assertEqual(y["mesh"], "B.msh")
        self.assertAlmostEqual(y["materials"]["epidermis"]["youngs_modulus_MPa"], 0.136)
        self.assertAlmostEqual(y["materials"]["dermis"]["poisson_ratio"], 0.48)
        self.assertAlmostEqual(y["pad_frame"]["tilt_deg"], 15.0)

    def test_b_coarse_sets(self):
        m = model("B_coarse")
        # config/models/README.md: B_coarse has 915 soft nodes and 3610 soft tets
        self.assertEqual(len(m.soft_nodes), 915)
        self.assertEqual(len(m.soft_tets), 3610)
        self.assertGreater(len(m.attached), 0)
        self.assertGreater(len(m.merkel), 0)
        for _, _, n in m.soft_tets:
            self.assertGreater(fingertip.signed_volume(*(m.nodes[t] for t in n)), 0)
        # Merkel triangles point from dermis to epidermis: the epidermis tet is on the + side.
        tissue_of_face = {}
        for _, tissue, n in m.soft_tets:
            for f in fingertip.FACE_VERTICES:
                tissue_of_face.setdefault(tuple(sorted(n[i] for i in f)), []).append((tissue, n))
        for tri in m.merkel[:50]:
            p = [m.nodes[v] for v in tri]
            normal = fingertip.cross(fingertip.sub(p[1], p[0]), fingertip.sub(p[2], p[0]))
            for tissue, n in tissue_of_face[tuple(sorted(tri))]:
                apex = [v for v in n if v not in tri][0]
                side = fingertip.dot(normal, fingertip.sub(m.nodes[apex], p[0]))
                self.assertEqual(side > 0, tissue == "epidermis")
        # Pad frame: origin on the skin with z_pad = 0, every skin node at z_pad <= 0.
        pad = m.pad_positions()
        self.assertTrue(all(pad[n][2] <= 1e-12 for n in m.skin_nodes()))
        self.assertIn(0.0, [round(pad[n][2], 12) for n in m.skin_nodes()])

    def test_model_c_is_homogeneous_and_a_has_shell(self):
        c = model("C")
        self.assertEqual({v["E_MPa"] for k, v in c.materials.items() if k in fingertip.SOFT}, {0.034})
        self.assertEqual(c.sc, [])
        a = model("A")
        self.assertGreater(len(a.sc), 0)
        self.assertAlmostEqual(a.sc_thickness_mm, 0.02)
        self.assertAlmostEqual(a.sc_material["E_MPa"], 1.993)
        self.assertEqual(len(a.merkel), len(c.merkel))


class ExporterTest(unittest.TestCase):
    def test_c3d10_mid_nodes_shared_and_corner_tags_kept(self):
        m = model("B_coarse")
        with tempfile.TemporaryDirectory() as d:
            inp = export_deck.export(m, d, "C3D10", increments=2)
            nodes, elems, kind = {}, [], None
            with open(inp) as f:
                lines = f.read().splitlines()
            fixed = set()
            for line in lines:
                if line.startswith("*"):
                    kind = "node" if line.startswith("*NODE,") else (
                        "tet" if "TYPE=C3D10" in line else ("fixed" if "NSET=FIXED" in line else None))
                    continue
                v = [s.strip() for s in line.split(",")]
                if kind == "fixed":
                    fixed.update(int(t) for t in v if t)
                elif kind == "node":
                    nodes[int(v[0])] = tuple(float(t) for t in v[1:4])
                elif kind == "tet":
                    elems.append([int(t) for t in v])
        edges = set()
        for _, _, n in m.soft_tets:
            for a, b in export_deck.C3D10_EDGES:
                edges.add((min(n[a], n[b]), max(n[a], n[b])))
        self.assertEqual(len(elems), len(m.soft_tets))
        # bone/nail surface: corner nodes and the mid-edge nodes of rigid edges are fixed
        rigid_edges = set()
        for _, _, n in m.rigid_tets:
            for a, b in export_deck.C3D10_EDGES:
                rigid_edges.add((min(n[a], n[b]), max(n[a], n[b])))
        expect = set(m.attached)
        for e in elems:
            for k, (a, b) in enumerate(export_deck.C3D10_EDGES):
                if (min(e[1 + a], e[1 + b]), max(e[1 + a], e[1 + b])) in rigid_edges:
                    expect.add(e[5 + k])
        self.assertEqual(fixed, expect)
        self.assertGreater(len(fixed), len(m.attached))
        mids = {t for e in elems for t in e[5:]}
        self.assertEqual(len(mids), len(edges))           # one shared node per edge
        self.assertTrue(min(mids) > max(m.nodes))         # above every Gmsh tag
        by_tag = {t: n for t, _, n in m.soft_tets}
        pad = m.pad_positions()
        for e in elems[:200]:
            self.assertEqual(e[1:5], by_tag[e[0]])       # Gmsh element and corner tags
            for k, (a, b) in enumerate(export_deck.C3D10_EDGES):
                mid = nodes[e[5 + k]]
                for i in range(3):
                    self.assertAlmostEqual(mid[i], 0.5 * (pad[e[1 + a]][i] + pad[e[1 + b]][i]), 9)


class ReaderTest(unittest.TestCase):
    DAT = """
 total force (fx,fy,fz) for set PLANEN and time  0.5000000E+00

        0.000000E+00  1.0E-20 -2.500000E-01

 displacements (vx,vy,vz) for set SLAVEN and time  0.5000000E+00

         7  1.0E-03 -2.0E-02 -8.0E-03

 internal energy density (elem, integ.pnt.,energy) for set MERKELADJ and time  0.5000000E+00

        16   1  1.0E-06
        16   2  3.0E-06
        17   1  2.0E-06

 total force (fx,fy,fz) for set PLANEN and time  0.1000000E+01

        0.000000E+00  1.0E-20 -5.000000E-01
"""

    def test_parse_dat(self):
        with tempfile.TemporaryDirectory() as d:
            p = os.path.join(d, "press.dat")
            with open(p, "w") as f:
                f.write(self.DAT)
            incs = read_results.parse_dat(p)
        self.assertEqual([i["time"] for i in incs], [0.5, 1.0])
        self.assertAlmostEqual(incs[0]["force"][2], -0.25)
        self.assertEqual(incs[0]["u"][7], (1e-3, -2e-2, -8e-3))
        self.assertEqual(incs[0]["ener"], {16: [1e-6, 3e-6], 17: [2e-6]})
        self.assertEqual(incs[1]["ener"], {})

    def test_vertex_average_and_path(self):
        m = model("B_coarse")
        mm = read_results.MerkelMap(m)
        esed = {t: float(t) for t, _, _ in m.soft_tets}
        vs = mm.vertex_sed(esed)
        for v in mm.vertices[:100]:
            adj = [t for t, _, n in m.soft_tets if v in n]   # ALL soft elements at v
            self.assertAlmostEqual(vs[v], sum(adj) / len(adj))
        # A field linear in x is reproduced exactly by the barycentric path.
        lin = {v: 3.0 + 2.0 * mm.pad[v][0] for v in mm.vertices}
        path = mm.sample_path(lin)
        self.assertGreater(len(path), 50)
        for x, val in path:
            self.assertAlmostEqual(val, 3.0 + 2.0 * x, 9)
        xs = [round(x, 6) for x, _ in path]
        self.assertEqual(xs, sorted(xs))
        self.assertTrue(all(abs(x * 10 - round(x * 10)) < 1e-6 for x in xs))  # 0.1 mm grid

    def test_one_sided_vertex_average(self):
        m = model("B_coarse")
        tissue = {t: g for t, g, _ in m.soft_tets}
        esed = {t: (2.0 if g == "epidermis" else 5.0 if g == "dermis" else 7.0) for t, g, _ in m.soft_tets}
        for side, value in (("epidermis", 2.0), ("dermis", 5.0)):
            mm = read_results.MerkelMap(m, side)
            vs = mm.vertex_sed(esed)
            for v in mm.vertices:
                self.assertTrue(all(tissue[e] == side for e in mm.adjacent[v]))
                self.assertAlmostEqual(vs[v], value)
        both = read_results.MerkelMap(m).vertex_sed(esed)
        self.assertTrue(any(2.0 < both[v] < 5.0 for v in both))  # the two-sided mean mixes them


class ComparePathsTest(unittest.TestCase):
    """compare_paths.py's normalizations and smoothing scale."""

    @staticmethod
    def path(f, peak_of_map=None):
        xs = [round(-6.0 + 0.1 * k, 6) for k in range(121)]
        ys = [f(x) for x in xs]
        top = peak_of_map if peak_of_map else max(ys)
        return {"x_mm": xs, "sed_Pa": ys, "sed_normalized": [y / top for y in ys]}

    def test_smoothing_keeps_a_constant_and_a_line(self):
        p = self.path(lambda x: 3.0)
        self.assertTrue(all(abs(y - 3.0) < 1e-12 for y in compare_paths.smoothed(p["x_mm"], p["sed_Pa"], 1.0)))
        line = self.path(lambda x: 2.0 + 0.5 * x)
        sm = compare_paths.smoothed(line["x_mm"], line["sed_Pa"], 0.5)
        mid = [i for i, x in enumerate(line["x_mm"]) if abs(x) < 3.0]  # away from the ends
        for i in mid:
            self.assertAlmostEqual(sm[i], line["sed_Pa"][i], 6)
        self.assertEqual(compare_paths.smoothed(line["x_mm"], line["sed_Pa"], 0.0), line["sed_Pa"])

    def test_path_normalization_ignores_the_map_maximum(self):
        # The same path shape under two map maxima 8 % apart: a map-normalized comparison sees
        # the offset, a path-normalized one does not.
        shape = lambda x: math.exp(-x * x / 4.0)  # noqa: E731
        a, b = self.path(shape, 1.0), self.path(shape, 1.08)
        mean_map = compare_paths.path_errors(compare_paths.prepared(a), compare_paths.prepared(b))[0]
        mean_path = compare_paths.path_errors(compare_paths.prepared(a, "path"), compare_paths.prepared(b, "path"))[0]
        self.assertGreater(mean_map, 0.02)
        self.assertLess(mean_path, 1e-12)
        self.assertAlmostEqual(max(compare_paths.prepared(a, "path", 0.5)["sed_normalized"]), 1.0)
        with self.assertRaises(ValueError):
            compare_paths.prepared(a, "peak")

    def test_smoothing_removes_a_ripple_finer_than_its_scale(self):
        shape = lambda x: math.exp(-x * x / 8.0)  # noqa: E731
        a = self.path(shape)
        b = self.path(lambda x: shape(x) * (1.0 + 0.1 * math.cos(2 * math.pi * x / 0.4)))  # 0.4 mm ripple
        raw = compare_paths.path_errors(compare_paths.prepared(a, "path"), compare_paths.prepared(b, "path"))[0]
        at_1mm = compare_paths.path_errors(compare_paths.prepared(a, "path", 1.0),
                                           compare_paths.prepared(b, "path", 1.0))[0]
        self.assertGreater(raw, 0.02)
        self.assertLess(at_1mm, 0.1 * raw)

    def test_plot_path_scale_writes_a_png_from_the_committed_table(self):
        import subprocess
        exe = fingertip.plot_python()
        if subprocess.call([exe, "-c", "import matplotlib"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL):
            self.skipTest("no matplotlib")
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "scale.png")
            subprocess.check_call([exe, os.path.join(REPO, "tools", "ccx", "plot_path_scale.py"),
                                   os.path.join(REPO, "docs", "validation", "path_scale", "path_scale.csv"), out],
                                  stdout=subprocess.DEVNULL)
            self.assertGreater(os.path.getsize(out), 10000)
            bad = subprocess.call([exe, os.path.join(REPO, "tools", "ccx", "plot_path_scale.py"),
                                   os.path.join(REPO, "docs", "validation", "path_scale", "path_scale.csv"), out,
                                   "--reference", "Z"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            self.assertNotEqual(bad, 0)

    def test_path_scale_study_compares_every_definition_scale_and_normalization(self):
        import path_scale_study
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "t.csv")
            sys.argv = ["path_scale_study.py", "--out", out]
            self.assertEqual(path_scale_study.main(), 0)
            import csv
            rows = list(csv.DictReader(open(out)))
        # both sides: A, A_coarse, B, C; one side: A_coarse, B, C; x 2 normalizations x 3 scales
        self.assertEqual(len(rows), (4 + 3 + 3) * 2 * 3)
        self.assertEqual({r["merkel_side"] for r in rows}, {"both", "epidermis", "dermis"})
        self.assertTrue(all(float(r["mean_abs_err"]) <= float(r["max_abs_err"]) for r in rows))


if __name__ == "__main__":
    unittest.main(verbosity=1)
