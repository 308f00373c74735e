#!/usr/bin/env python3
"""CalculiX reference run of the paper's press experiment, written like `sedbridge press`.

usage: run_reference.py --model A|B|C|PATH [--element C3D4|C3D10] [--increments 50]
                        [--threads 2] [--contact-slope 50] [--no-shells] [--target-force 1.0]
                        [--material-law elastic|neohooke] --out DIR

Exports the deck (tools/ccx/export_deck.py), runs `ccx` in DIR/ccx/ showing one progress
line per increment, then reads DIR/ccx/press.dat (tools/ccx/read_results.py) and writes
DIR/force_displacement.csv, DIR/merkel_sed.csv, DIR/sed_path.csv and the plots of
tools/plot_press.py. A failed ccx run (error, no convergence, stopped before the full
displacement) exits with status 1 and prints ccx's own messages; no CSV is written then
(unless --allow-partial, which writes the converged increments and says so).
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import export_deck  # noqa: E402
import fingertip  # noqa: E402
import read_results  # noqa: E402

REPO = os.path.abspath(os.path.join(HERE, "..", ".."))


def run_ccx(run_dir, threads, log, quiet=False):
    """Runs ccx on run_dir/press.inp; returns (ok, final_time, error_lines)."""
    exe = shutil.which("ccx")
    if not exe:
        raise SystemExit("run_reference: `ccx` not found (Debian package calculix-ccx)")
    env = dict(os.environ, OMP_NUM_THREADS=str(threads), CCX_NPROC_STIFFNESS=str(threads),
               CCX_NPROC_EQUATION_SOLVER=str(threads))
    t0 = time.time()
    errors, final_time, inc, iters = [], 0.0, 0, 0
    finished = False
    with open(log, "w") as logf:
        p = subprocess.Popen([exe, "-i", "press"], cwd=run_dir, env=env, stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, text=True, bufsize=1)
        tail = []
        for line in p.stdout:
            logf.write(line)
            s = line.strip()
            tail = (tail + [s])[-40:]
            if "*ERROR" in s or "ERROR" in s.upper().split(":")[0]:
                errors.append(s)
            m = re.match(r"increment\s+(\d+)\s+attempt\s+(\d+)", s)
            if m:
                inc = int(m.group(1))
                if int(m.group(2)) > 1 and not quiet:
                    print(f"  ccx: increment {inc}: attempt {m.group(2)} (cut back)", flush=True)
            if re.match(r"iteration\s+\d+", s):
                iters += 1
            m = re.match(r"actual total time=\s*(\S+)", s)
            if m:
                final_time = float(m.group(1).replace("D", "E"))
                if not quiet:
                    print(f"  ccx: increment {inc:3d} -> time {final_time:.4f} "
                          f"({iters} Newton iterations so far, {time.time() - t0:6.1f} s)", flush=True)
            if "Job finished" in s:
                finished = True
        p.wait()
    nonlinear = final_time > 0
    ok = p.returncode == 0 and finished and not errors and (final_time > 1.0 - 1e-6 or not nonlinear)
    if not ok and not errors:
        errors = [l for l in tail if l][-15:]
    return ok, final_time, errors, time.time() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    export_deck.add_deck_arguments(ap)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--target-force", type=float, default=1.0,
                    help="the SED map and path are taken at the increment closest to this force [N]")
    ap.add_argument("--allow-partial", action="store_true")
    ap.add_argument("--no-plots", action="store_true")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()

    t_start = time.time()
    model = fingertip.load_model(a.model, REPO)
    run_dir = os.path.join(a.out, "ccx")
    for stale in ("press.dat", "press.frd", "press.sta", "press.cvg"):
        if os.path.exists(os.path.join(run_dir, stale)):
            os.remove(os.path.join(run_dir, stale))
    export_deck.export_from_args(model, run_dir, a)
    with open(os.path.join(run_dir, "deck.json")) as f:
        meta = json.load(f)
    print(f"run_reference: model {model.name} ({a.element}, {meta['soft_tets']} tets, {meta['nodes']} nodes, "
          f"shells: {meta['shells']}), {a.increments} increments -> {run_dir}/press.inp", flush=True)
    ok, final_time, errors, wall = run_ccx(run_dir, a.threads, os.path.join(run_dir, "ccx.log"))
    meta.update(ccx_wall_s=round(wall, 1), ccx_ok=ok, ccx_final_time=final_time, threads=a.threads)
    if not ok:
        print(f"run_reference: ccx FAILED after {wall:.0f} s (reached time {final_time:.4f} of 1.0, "
              f"i.e. {final_time * a.depth_mm:.3f} mm). ccx said:", file=sys.stderr)
        for e in errors:
            print("  | " + e, file=sys.stderr)
        print(f"  full log: {run_dir}/ccx.log", file=sys.stderr)
        if not a.allow_partial or final_time <= 0:
            json.dump(meta, open(os.path.join(run_dir, "deck.json"), "w"), indent=1)
            return 1
        print("run_reference: --allow-partial: writing the converged increments only", file=sys.stderr)
    try:
        r = read_results.read_run(model, run_dir, a.target_force)
    except read_results.ResultError as e:
        print(f"run_reference: cannot read the results: {e}", file=sys.stderr)
        return 1
    read_results.write_csvs(r, a.out)
    s = r["steps"][r["selected"]]
    meta.update(total_wall_s=round(time.time() - t_start, 1), selected_step=s[0],
                selected_force_N=s[2], max_merkel_sed_Pa=r["max_sed"])
    json.dump(meta, open(os.path.join(a.out, "run.json"), "w"), indent=1)
    print(f"run_reference: ccx {wall:.0f} s; {len(r['steps'])} increments; F({r['steps'][-1][1]:.2f} mm) = {r['steps'][-1][2]:.4f} N; "
          f"selected step {s[0]} (d = {s[1]:.2f} mm, F = {s[2]:.4f} N); max Merkel SED {r['max_sed']:.1f} Pa")
    if not a.no_plots:
        rc = subprocess.call([fingertip.plot_python(), os.path.join(REPO, "tools", "plot_press.py"), a.out,
                              "--labels", f"{model.name}-ccx-{a.element}", "--out", a.out])
        if rc != 0:
            print("run_reference: plotting failed (CSV files are written)", file=sys.stderr)
    print(f"run_reference: wrote {a.out}/force_displacement.csv, merkel_sed.csv, sed_path.csv")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
