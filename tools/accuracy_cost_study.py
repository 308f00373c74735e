#!/usr/bin/env python3
"""What accuracy costs in time: sweep the solver knobs of the press experiment and measure
ms/step and the SED error against a reference run (docs/accuracy-cost.md).

usage: accuracy_cost_study.py --reference DIR [--out out/accuracy_cost] [--quick] [--plot-only]
                              [--sedbridge build/sedbridge] [--only NAME,...] [--rescore]
                              [--runs DIR] [--times CSV]

REFERENCE is a press-shaped result folder (sed_path.csv, merkel_sed.csv,
force_displacement.csv), e.g. CalculiX model A from tools/ccx/run_reference.py. Every
configuration runs `sedbridge press` on a scene derived from config/scenes/paper_press.yaml
and is compared with tools/ccx/compare_paths.py's path_errors. Writes OUT/study.csv
(one row per configuration), OUT/pareto.png (median ms/step vs normalized-path MAE) and
prints a markdown table. Each run's own folder stays in OUT/<name>/. A study run by
tools/study.py (`study.py make accuracy-cost`) is scored with --rescore --runs STUDY/cases
--times STUDY/summary.csv (the run folders and their wall seconds).
"""
import argparse
import csv
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.abspath(os.path.join(HERE, ".."))
sys.path.insert(0, os.path.join(HERE, "ccx"))
import compare_paths  # noqa: E402

BASE = os.path.join(REPO, "config", "scenes", "paper_press.yaml")


def scene_yaml(model="B", elasticity="corotational", integrator="quasi_static", dt_s=None, steps=50,
               newton=25, solver="ldlt", tol=1e-6, max_it=200, k_contact=10000, preset=None, fallback=True):
    """The paper press with one or more knobs changed (same plane, same 2 mm over t in [0, 1]).
    With `preset`, the elasticity, solver and Newton count are left to the preset."""
    if integrator == "backward_euler":
        steps = int(round(1.0 / dt_s))
    lines = [f"model: {model}"]
    if preset:
        lines.append(f"preset: {preset}")
    if not preset:
        lines.append(f"elasticity: {elasticity}")
    lines += ["dynamics:",
              f"  integrator: {integrator}",
              f"  steps: {steps}"]
    if not preset:
        lines.append(f"  newton_iterations: {newton}")
    if integrator == "backward_euler":
        lines.append(f"  dt_s: {dt_s}")
    else:
        lines.append("  newton_tolerance_mm: 1.0e-6")
    if not preset:
        lines.append(f"solver: {{type: {solver}, tolerance: {tol}, max_iterations: {max_it}, "
                     f"fallback_to_direct: {'true' if fallback else 'false'}}}")
    lines += [
              "bone: {mode: fixed, stiffness_N_m: 200, damping_N_s_m: 0.1, anisotropy: 1.0}",
              "contact:",
              f"  stiffness_N_m: {k_contact}",
              "  damping_N_s_m: 0.5",
              "  objects:",
              "    - {name: plane, shape: plane, rpy_deg: [180, 0, 0], position_mm: [0, 0, 0],",
              "       motion: {keyframes: [{t_s: 0.0, offset_mm: [0, 0, 0]}, {t_s: 1.0, offset_mm: [0, 0, -2.0]}]}}",
              "outputs: {merkel_sed: true, full_sed: false, vtu_every: 0}"]
    return "\n".join(lines) + "\n"


def force_at_depth(fd_rows, depth_mm):
    """Force [N] at `depth_mm` of a force_displacement.csv, linear between the steps around it
    (the reference and the runs step the press differently)."""
    d = [0.0] + [float(r["displacement_mm"]) for r in fd_rows]
    f = [0.0] + [float(r["force_N"]) for r in fd_rows]
    for k in range(1, len(d)):
        if d[k] >= depth_mm:
            t = (depth_mm - d[k - 1]) / (d[k] - d[k - 1])
            return f[k - 1] + t * (f[k] - f[k - 1])
    return float("nan")


def configurations(quick):
    c = []
    # Mesh resolution (corotational, exact solves; the finer meshes with the warped-PCG
    # solve, which gives the exact solve's path to three digits on B and is much cheaper).
    for m in (["B_coarse", "B"] if quick else ["B_coarse", "B"]):
        c.append((f"{m}_corot_ldlt", dict(model=m)))
    if not quick:
        for m in ["B_coarse", "B_fine", "B_x4"]:  # B: the B_corot_pcgwarp_tol1e-06 row
            c.append((f"{m}_corot_pcgwarp", dict(model=m, solver="pcg_warp", tol=1e-6)))
    # Element formulation.
    c.append(("B_linear_ldlt", dict(model="B", elasticity="linear")))
    # Contact by the compliance method (linear, quasi-static; same answer as B_linear_ldlt).
    c.append(("B_linear_compliance", dict(model="B", elasticity="linear", solver="compliance")))
    # The locking-free average nodal pressure tet (docs/validation.md): exact Newton, and
    # the real-time form (backward Euler, one linearized solve). Block-Jacobi PCG: its
    # matrix couples 2-rings, whose factor (pcg_warp's preconditioner) is ~4x denser.
    c.append(("B_nodalpressure_pcgjacobi", dict(model="B", elasticity="nodal_pressure", solver="pcg_jacobi", tol=1e-6,
                                                max_it=2000)))
    if not quick:
        c.append(("B_nodalpressure_be_dt0.01", dict(model="B", elasticity="nodal_pressure", integrator="backward_euler",
                                                    dt_s=0.01, newton=1, solver="pcg_jacobi", max_it=2000)))
    # Linear solver, tolerance, iteration cap, preconditioner.
    for tol in ([1e-4, 1e-6] if quick else [1e-3, 1e-4, 1e-6, 1e-8]):
        c.append((f"B_corot_pcgwarp_tol{tol:g}", dict(model="B", solver="pcg_warp", tol=tol)))
    c.append(("B_corot_pcgjacobi_tol1e-6", dict(model="B", solver="pcg_jacobi", tol=1e-6, max_it=2000)))
    if not quick:
        # Incomplete Cholesky needs more iterations than the exact warped factor.
        c.append(("B_corot_pcgwarpichol_tol1e-6", dict(model="B", solver="pcg_warp_ichol", tol=1e-6, max_it=2000)))
        # Iteration cap: the capped PCG iterate is used as is (no direct fallback), the next
        # Newton iteration / time step corrects what it left.
        for cap in [10, 3]:
            c.append((f"B_corot_pcgwarp_cap{cap}", dict(model="B", solver="pcg_warp", tol=1e-8, max_it=cap,
                                                       fallback=False)))
    # Penalty stiffness.
    for k in ([1e3, 1e5] if quick else [1e3, 1e5, 1e6]):
        c.append((f"B_corot_k{k:g}", dict(model="B", solver="pcg_warp", k_contact=k)))
    # Quasi-static vs backward Euler (2 mm in 1 s), one linearized solve a step.
    for dt in ([0.01] if quick else [0.02, 0.01, 0.005]):
        c.append((f"B_corot_be_dt{dt:g}", dict(model="B", integrator="backward_euler", dt_s=dt, newton=1,
                                               solver="pcg_warp")))
    if not quick:
        c.append(("B_linear_be_dt0.01", dict(model="B", elasticity="linear", integrator="backward_euler",
                                             dt_s=0.01, newton=1, solver="pcg_warp")))
        for cap in [3, 1]:
            c.append((f"B_corot_be_dt0.01_cap{cap}", dict(model="B", integrator="backward_euler", dt_s=0.01, newton=1,
                                                         solver="pcg_warp", tol=1e-8, max_it=cap, fallback=False)))
        # The named presets as scenes select them (backward Euler, dt 10 ms, the real-time form):
        # only `preset:` is set, so the preset's own elasticity / solver / Newton count apply.
        for p in ["fast", "balanced", "accurate"]:
            c.append((f"preset_{p}_be_dt0.01", dict(model="B", integrator="backward_euler", dt_s=0.01, preset=p)))
    return c


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def family(name):
    """The knob a configuration varies, for the plot's colours."""
    if name.startswith("preset_"):
        return "preset"
    if name.startswith("B_coarse") or name.startswith("B_fine") or name.startswith("B_x4"):
        return "mesh"
    if "_be_" in name:
        return "integrator"
    if "linear" in name or "nodalpressure" in name:
        return "elasticity"
    if "_k" in name:
        return "contact penalty"
    return "solver"


def pareto_front(points):
    """Indices of the points no other point beats in both coordinates (smaller is better)."""
    front = []
    for i, (x, y) in enumerate(points):
        if not any((x2 <= x and y2 <= y) and (x2 < x or y2 < y) for x2, y2 in points):
            front.append(i)
    return sorted(front, key=lambda i: points[i][0])


def write_pareto(rows, path):
    """Whole-press time against the path error and the force error, Pareto front marked."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("pareto plot skipped: no matplotlib (run with /usr/bin/python3)", file=sys.stderr)
        return
    fams = sorted({family(r["name"]) for r in rows})
    colors = dict(zip(fams, plt.rcParams["axes.prop_cycle"].by_key()["color"]))
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.2))
    for ax, key, label in [(axes[0], "path_mae", "normalized SED path MAE vs reference"),
                           (axes[1], "force_2mm_rel_err", "|force error at 2 mm| vs reference")]:
        pts = [(float(r["total_s"]), abs(float(r[key]))) for r in rows]
        front = pareto_front(pts)
        for i, (r, (x, y)) in enumerate(zip(rows, pts)):
            f = family(r["name"])
            ax.scatter(x, y, color=colors[f], label=f)
            # Names only where they say something (the front, mesh, formulation, presets);
            # the solver-knob cluster is in study.csv and the doc's table.
            if i in front or f in ("mesh", "elasticity", "preset"):
                ax.annotate(r["name"], (x, y), fontsize=6.5, xytext=(3, 3), textcoords="offset points")
        ax.plot([pts[i][0] for i in front], [pts[i][1] for i in front], "k--", lw=0.8, label="Pareto front")
        ax.set_xscale("log")
        ax.set_xlabel("whole press, wall s (this machine)")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        handles, labels = ax.get_legend_handles_labels()
        seen = {}
        for h, l in zip(handles, labels):
            seen.setdefault(l, h)
        ax.legend(seen.values(), seen.keys(), fontsize=7)
    fig.suptitle("What accuracy costs in time: the press experiment on model B variants")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f"wrote {path}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--reference", help="the reference run folder (required unless --plot-only)")
    ap.add_argument("--out", default=os.path.join(REPO, "out", "accuracy_cost"))
    ap.add_argument("--sedbridge", default=os.path.join(REPO, "build", "sedbridge"))
    ap.add_argument("--quick", action="store_true", help="fewer configurations")
    ap.add_argument("--only", default="", help="comma-separated configuration names")
    ap.add_argument("--plot-only", action="store_true", help="redraw OUT/pareto.png from OUT/study.csv, run nothing")
    ap.add_argument("--rescore", action="store_true",
                    help="run nothing: score the run folders already in OUT against --reference (a new reference); "
                         "times come from OUT/study.csv")
    ap.add_argument("--runs", help="--rescore: the run folders' parent (default: --out)")
    ap.add_argument("--times", help="--rescore: the times from this CSV's case and wall_s columns "
                                    "(tools/study.py's summary.csv) instead of OUT/study.csv")
    a = ap.parse_args()
    if a.plot_only:
        write_pareto(read_csv(os.path.join(a.out, "study.csv")), os.path.join(a.out, "pareto.png"))
        return 0
    if not a.reference:
        ap.error("--reference is required")
    os.makedirs(a.out, exist_ok=True)
    ref = compare_paths.read_cols(os.path.join(a.reference, "sed_path.csv"))
    ref_fd = read_csv(os.path.join(a.reference, "force_displacement.csv"))
    ref_force_2mm = float(ref_fd[-1]["force_N"])
    ref_force_1mm = force_at_depth(ref_fd, 1.0)
    ref_max_sed = max(float(r["sed_Pa"]) for r in read_csv(os.path.join(a.reference, "merkel_sed.csv")))
    configs = configurations(a.quick)
    if a.only:
        keep = set(a.only.split(","))
        configs = [c for c in configs if c[0] in keep]
    study_csv = os.path.join(a.out, "study.csv")
    earlier = {r["name"]: r for r in read_csv(study_csv)} if a.rescore and os.path.exists(study_csv) else {}
    if a.rescore and a.times:
        earlier = {r["case"]: dict(total_s=r["wall_s"]) for r in read_csv(a.times) if r["status"] == "ok"}
    runs = a.runs if a.rescore and a.runs else a.out
    rows = []
    for i, (name, kw) in enumerate(configs, 1):
        d = os.path.join(runs, name)
        if a.rescore:
            if not os.path.exists(os.path.join(d, "sed_path.csv")):
                continue
            wall = float(earlier.get(name, {}).get("total_s", "nan"))
            load = float(earlier.get(name, {}).get("load_avg_1min", "nan"))
        else:
            os.makedirs(d, exist_ok=True)
            scene = os.path.join(d, "scene.yaml")
            with open(scene, "w") as f:
                f.write(scene_yaml(**kw))
            print(f"[{i}/{len(configs)}] {name} ...", flush=True)
            t0 = time.time()
            r = subprocess.run([a.sedbridge, "press", "--scene", scene, "--out", d, "--no-plots", "--quiet"],
                               capture_output=True, text=True)
            wall = time.time() - t0
            # 1-min load average after the run: times from a loaded machine are not comparable
            load = os.getloadavg()[0]
            if r.returncode != 0:
                print(f"  failed: {r.stderr.strip() or r.stdout.strip()}", file=sys.stderr)
                continue
        timing = read_csv(os.path.join(d, "step_timing.csv"))
        ms = sorted(float(t["wall_ms"]) for t in timing)
        med = statistics.median(ms)
        p99 = ms[min(len(ms) - 1, int(0.99 * len(ms)))]
        run = compare_paths.read_cols(os.path.join(d, "sed_path.csv"))
        mae, mx, n, _, _ = compare_paths.path_errors(ref, run)
        fd = read_csv(os.path.join(d, "force_displacement.csv"))
        force_2mm = float(fd[-1]["force_N"])
        force_1mm = force_at_depth(fd, 1.0)
        max_sed = max(float(x["sed_Pa"]) for x in read_csv(os.path.join(d, "merkel_sed.csv")))
        row = dict(name=name, steps=len(timing), median_ms=med, p99_ms=p99, total_s=wall, path_mae=mae, path_max=mx,
                   max_sed_rel_err=(max_sed - ref_max_sed) / ref_max_sed,
                   force_1mm_rel_err=(force_1mm - ref_force_1mm) / ref_force_1mm,
                   force_2mm_rel_err=(force_2mm - ref_force_2mm) / ref_force_2mm,
                   unconverged=sum(1 for t in timing if t["converged"] != "1"),
                   fallbacks=sum(int(t["solver_fallbacks"]) for t in timing),
                   max_inverted=max(int(t["inverted_elements"]) for t in timing),
                   load_avg_1min=load)
        rows.append(row)
        print(f"  {med:.1f} ms/step median, p99 {p99:.1f}; path MAE {mae:.3f} max {mx:.3f}; "
              f"max SED {100 * row['max_sed_rel_err']:+.1f} %; F(1 mm) {100 * row['force_1mm_rel_err']:+.1f} %; "
              f"F(2 mm) {100 * row['force_2mm_rel_err']:+.1f} %", flush=True)
    if not rows:
        return 1
    with open(study_csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    print("\n| configuration | steps | median ms/step | p99 ms/step | path MAE | path max | max SED err | F(1 mm) err | F(2 mm) err | unconverged | fallbacks |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['name']} | {r['steps']} | {r['median_ms']:.1f} | {r['p99_ms']:.1f} | {r['path_mae']:.3f} | "
              f"{r['path_max']:.3f} | {100 * r['max_sed_rel_err']:+.1f} % | {100 * r['force_1mm_rel_err']:+.1f} % | "
              f"{100 * r['force_2mm_rel_err']:+.1f} % | "
              f"{r['unconverged']} | {r['fallbacks']} |")
    timed = [r for r in rows if r["total_s"] == r["total_s"]]  # NaN: rescored without an earlier time
    if timed:
        write_pareto(timed, os.path.join(a.out, "pareto.png"))
    else:
        print("pareto plot skipped: no run times (rescored folders without an earlier study.csv)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
