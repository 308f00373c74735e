#!/usr/bin/env python3
"""ParaView's Warp By Vector on sedbridge's VTUs, through VTK itself (vtkWarpVector is the
filter behind it): the file's active vectors are displacement_mm, the stored points are the
reference shape, so warping with scale 1 gives reference + displacement, applied once.

  test_vtk_warp.py --sedbridge build/sedbridge --work DIR
Needs VTK's Python module (Debian: python3-vtk9, not installed by tools/setup.sh: it is
large); exits 77 (skip) without it.
"""

import argparse
import os
import subprocess
import sys

try:
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
    from vtkmodules.vtkFiltersGeneral import vtkWarpVector
except ImportError as e:
    print("skip: no VTK Python module (apt-get install python3-vtk9): %s" % e)
    sys.exit(77)


def read(path):
    r = vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    return r


def points(data):
    p = data.GetPoints()
    return [p.GetPoint(i) for i in range(p.GetNumberOfPoints())]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sedbridge", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
    a = ap.parse_args()
    out = os.path.join(a.work, "replay_vtu")
    env = dict(os.environ, LCM_DEFAULT_URL="memq://")
    # The pressure map's reduced step writes full-field frames (the default contact step does not).
    os.makedirs(a.work, exist_ok=True)
    config = os.path.join(a.work, "reduced.yaml")
    with open(os.path.join(a.root, "config/bridge/default.yaml")) as f:
        text = f.read()
    with open(config, "w") as f:
        f.write(text.replace("step: contact", "step: reduced"))
    subprocess.run([a.sedbridge, "replay", os.path.join(a.root, "config/bridge/example_press.log"), "--config", config,
                    "--out", out, "--vtu-every", "150", "--no-plots", "--quiet"], check=True, stdout=subprocess.DEVNULL,
                   env=env)
    rest_reader = read(os.path.join(out, "frame_000000.vtu"))
    pressed_reader = read(os.path.join(out, "frame_000150.vtu"))
    rest, pressed = rest_reader.GetOutput(), pressed_reader.GetOutput()
    failures = []
    if pressed.GetNumberOfCells() == 0:
        failures.append("VTK read no cells")
    vectors = pressed.GetPointData().GetVectors()
    if vectors is None or vectors.GetName() != "displacement_mm":
        failures.append("active vectors are %r, not displacement_mm" % (vectors and vectors.GetName()))
    if points(rest) != points(pressed):
        failures.append("the stored points differ between frames: they must be the reference shape")
    names = [pressed.GetFieldData().GetArrayName(i) for i in range(pressed.GetFieldData().GetNumberOfArrays())]
    if "tissue_0_epidermis" not in names:
        failures.append("FieldData has no tissue_0_epidermis: %s" % names)
    warp = vtkWarpVector()  # what ParaView's Warp By Vector runs, with its default vectors
    warp.SetInputConnection(pressed_reader.GetOutputPort())
    warp.SetScaleFactor(1.0)
    warp.Update()
    warped = points(warp.GetOutput())
    disp = [vectors.GetTuple3(i) for i in range(vectors.GetNumberOfTuples())] if vectors else []
    worst, moved = 0.0, 0.0
    for p, q, d in zip(points(pressed), warped, disp):
        worst = max(worst, max(abs(q[k] - (p[k] + d[k])) for k in range(3)))
        moved = max(moved, max(abs(d[k]) for k in range(3)))
    if worst > 1e-9:
        failures.append("warped != reference + displacement (worst %g mm)" % worst)
    if not 1e-3 < moved < 5.0:
        failures.append("largest displacement %g mm is not a press of the pad" % moved)
    for f in failures:
        print("FAIL:", f)
    print("vtk %s: %d points, largest displacement %.3f mm, warp error %.2g mm"
          % (__import__("vtkmodules").__version__ if hasattr(__import__("vtkmodules"), "__version__") else "9",
             len(warped), moved, worst))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
