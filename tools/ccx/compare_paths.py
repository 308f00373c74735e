#!/usr/bin/env python3
"""Table III of the paper: errors of normalized SED path plots against a reference run.

usage: compare_paths.py REF_DIR RUN_DIR [RUN_DIR ...] [--labels REF,RUN1,...]
                        [--csv OUT.csv] [--plot OUTDIR] [--normalize map|path] [--smooth-mm S]

Each DIR holds sed_path.csv (x_mm, sed_Pa, sed_normalized) as written by `sedbridge press`
or tools/ccx/run_reference.py. Both paths are put on a common grid: the reference's x
samples inside the x range the two paths share, the run linearly interpolated there. Prints
a markdown table with the mean and max absolute error of sed_normalized, the grid size and
range, and (extra) the relative error of the map maximum SED and of the force at the last
step. With --plot, runs tools/plot_press.py on all dirs (Figs 6, 7, 10-12 overlaid).

--normalize map (default) is the paper's Table III: SED divided by the maximum of each
Merkel map (sed_normalized as written). --normalize path divides each path by its own
maximum instead: a comparison of shape along the path that does not hinge on the single
vertex holding the map maximum (docs/validation.md, "At what scale does the reference
converge"). --smooth-mm S first averages each path with a Gaussian of standard deviation S
along x (its own samples, resampled at 0.05 mm; near the ends the weights are renormalized
over the samples that exist), i.e. compares at a spatial scale of about S.
"""
import argparse
import csv
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fingertip  # noqa: E402

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))


def read_cols(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise SystemExit(f"compare_paths: {path} is empty")
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def interp(xs, ys, x):
    if x <= xs[0]:
        return ys[0]
    if x >= xs[-1]:
        return ys[-1]
    lo, hi = 0, len(xs) - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if xs[mid] <= x:
            lo = mid
        else:
            hi = mid
    t = (x - xs[lo]) / (xs[hi] - xs[lo]) if xs[hi] > xs[lo] else 0.0
    return ys[lo] + t * (ys[hi] - ys[lo])


def smoothed(xs, ys, sigma_mm, step_mm=0.05):
    """ys averaged along x with a Gaussian of standard deviation sigma_mm (0: unchanged),
    evaluated at xs; each path only uses its own samples (weights renormalized near the ends)."""
    if sigma_mm <= 0:
        return list(ys)
    n = int(round((xs[-1] - xs[0]) / step_mm))
    fine_x = [xs[0] + k * (xs[-1] - xs[0]) / max(n, 1) for k in range(n + 1)]
    fine_y = [interp(xs, ys, x) for x in fine_x]
    out = []
    for x0 in xs:
        w = [math.exp(-0.5 * ((x - x0) / sigma_mm) ** 2) for x in fine_x]
        out.append(sum(wi * yi for wi, yi in zip(w, fine_y)) / sum(w))
    return out


def prepared(path, normalize="map", smooth_mm=0.0):
    """The path's x and the values compared: sed_normalized (map) or sed_Pa over its own
    maximum (path), after smoothing."""
    if normalize not in ("map", "path"):
        raise ValueError(f"normalize: 'map' or 'path', not {normalize!r}")
    if normalize == "map":
        return {"x_mm": path["x_mm"], "sed_normalized": smoothed(path["x_mm"], path["sed_normalized"], smooth_mm)}
    ys = smoothed(path["x_mm"], path["sed_Pa"], smooth_mm)
    top = max(ys)
    return {"x_mm": path["x_mm"], "sed_normalized": [y / top if top > 0 else 0.0 for y in ys]}


def path_errors(ref, run):
    """Mean and max |run - ref| of sed_normalized on the reference's x inside the shared range."""
    lo = max(ref["x_mm"][0], run["x_mm"][0])
    hi = min(ref["x_mm"][-1], run["x_mm"][-1])
    grid = [x for x in ref["x_mm"] if lo - 1e-9 <= x <= hi + 1e-9]
    if not grid:
        raise SystemExit("compare_paths: the paths share no x range")
    errs = [abs(interp(run["x_mm"], run["sed_normalized"], x) - interp(ref["x_mm"], ref["sed_normalized"], x))
            for x in grid]
    return sum(errs) / len(errs), max(errs), len(grid), lo, hi


def selected(fd, target):
    i = min(range(len(fd["force_N"])), key=lambda k: abs(fd["force_N"][k] - target))
    return f"{fd['displacement_mm'][i]:.2f} mm / {fd['force_N'][i]:.3f} N"


def max_sed(d):
    return max(read_cols(os.path.join(d, "merkel_sed.csv"))["sed_Pa"])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dirs", nargs="+", help="reference dir first")
    ap.add_argument("--labels", default="")
    ap.add_argument("--csv", default=None)
    ap.add_argument("--plot", default=None, help="write overlaid plots into this dir")
    ap.add_argument("--target-force", type=float, default=1.0,
                    help="only for the 'map at' column: the step closest to this force [N]")
    ap.add_argument("--normalize", choices=("map", "path"), default="map",
                    help="divide by each map's maximum (the paper's, default) or by each path's own maximum")
    ap.add_argument("--smooth-mm", type=float, default=0.0,
                    help="Gaussian standard deviation along x before comparing [mm] (default 0: none)")
    a = ap.parse_args()
    if len(a.dirs) < 2:
        ap.error("need a reference and at least one run")
    labels = a.labels.split(",") if a.labels else [os.path.basename(os.path.normpath(d)) for d in a.dirs]
    if len(labels) != len(a.dirs):
        ap.error("--labels needs one label per dir")
    ref_dir = a.dirs[0]
    if a.smooth_mm < 0:
        ap.error("--smooth-mm must be >= 0")
    ref = prepared(read_cols(os.path.join(ref_dir, "sed_path.csv")), a.normalize, a.smooth_mm)
    ref_fd = read_cols(os.path.join(ref_dir, "force_displacement.csv"))
    ref_max = max_sed(ref_dir)
    rows = []
    how = "each map's maximum" if a.normalize == "map" else "each path's own maximum"
    scale = f", Gaussian-smoothed along x (sigma {a.smooth_mm:g} mm)" if a.smooth_mm > 0 else ""
    print(f"Errors of the normalized SED path (y = 2 mm; divided by {how}{scale}) against {labels[0]}\n")
    print("| run | mean abs. err. | max abs. err. | grid (x range) | map at (d / F) | max SED [Pa] (vs ref) "
          "| F at last step [N] (vs ref) |")
    print("|---|---|---|---|---|---|---|")
    print(f"| {labels[0]} (reference) | - | - | {len(ref['x_mm'])} pts | {selected(ref_fd, a.target_force)} "
          f"| {ref_max:.1f} | {ref_fd['force_N'][-1]:.3f} |")
    for d, label in zip(a.dirs[1:], labels[1:]):
        run = prepared(read_cols(os.path.join(d, "sed_path.csv")), a.normalize, a.smooth_mm)
        fd = read_cols(os.path.join(d, "force_displacement.csv"))
        mean, mx, n, lo, hi = path_errors(ref, run)
        m = max_sed(d)
        f_last = fd["force_N"][-1]
        rows.append(dict(run=label, mean_abs_err=mean, max_abs_err=mx, grid_points=n, x_lo=lo, x_hi=hi,
                         max_sed_Pa=m, max_sed_rel_err=(m - ref_max) / ref_max,
                         force_last_N=f_last, force_rel_err=(f_last - ref_fd["force_N"][-1]) / ref_fd["force_N"][-1]))
        print(f"| {label} | {mean:.3f} | {mx:.3f} | {n} pts ({lo:.1f} to {hi:.1f} mm) | {selected(fd, a.target_force)} | {m:.1f} ({rows[-1]['max_sed_rel_err']:+.0%}) "
              f"| {f_last:.3f} ({rows[-1]['force_rel_err']:+.0%}) |")
    if a.csv:
        os.makedirs(os.path.dirname(os.path.abspath(a.csv)), exist_ok=True)
        with open(a.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
            w.writeheader()
            for r in rows:
                w.writerow(r)
    if a.plot:
        return subprocess.call([fingertip.plot_python(), os.path.join(REPO, "tools", "plot_press.py"), *a.dirs,
                                "--labels", ",".join(labels), "--out", a.plot])
    return 0


if __name__ == "__main__":
    sys.exit(main())
