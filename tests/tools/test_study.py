#!/usr/bin/python3
"""tools/study.py: the three shipped studies' manifests and a bad one; then, on a real
`dask-scheduler` and two `dask-worker` processes on 127.0.0.1, 20 short cases with one worker
killed while it runs a case (every case completes exactly once, the killed one's again on the
other worker), a crashing and a timed-out case reported while the others' results are kept, a
rerun that runs only the failed cases, an interrupted study resumed that runs only the cases it
had not recorded. Exits 77 (skip) after the manifest checks where distributed is not
importable (Debian: python3-distributed)."""
import argparse
import csv
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time

parser = argparse.ArgumentParser()
parser.add_argument("--root", required=True)
parser.add_argument("--sedbridge", required=True)
parser.add_argument("--work", required=True)
args = parser.parse_args()
STUDY = os.path.join(args.root, "tools", "study.py")
W = os.path.abspath(args.work)
shutil.rmtree(W, ignore_errors=True)
os.makedirs(W)
LEDGER, STARTS, FLAG = os.path.join(W, "ledger"), os.path.join(W, "starts"), os.path.join(W, "crash_fixed")
os.makedirs(LEDGER)
os.makedirs(STARTS)
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


def tool(*argv):
    r = subprocess.run([sys.executable, STUDY] + list(argv), capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


# The three shipped studies' manifests (no Dask needed): their cases, listed by --dry-run.
gen = os.path.join(W, "gen")
rc, text = tool("make", "fidelity-random", "--seeds", "1-3,7", "--presses", "5", "--manifest", f"{gen}/f.jsonl")
rc2, text = tool("run", f"{gen}/f.jsonl", "--out", f"{gen}/f", "--sedbridge", args.sedbridge, "--dry-run")
check(rc == 0 and rc2 == 0 and "4 to run" in text and re.search(r"seed_7: \S+ fidelity --synthetic --random 5 --seed 7 ", text),
      "fidelity-random: a case a seed")
rc, text = tool("make", "accuracy-cost", "--quick", "--reference", args.root, "--manifest", f"{gen}/a.jsonl")
rc2, text = tool("run", f"{gen}/a.jsonl", "--out", f"{gen}/a", "--sedbridge", args.sedbridge, "--dry-run")
check(rc == 0 and rc2 == 0 and "B_corot_ldlt: " in text and os.path.isfile(f"{gen}/accuracy_cost_scenes/B_corot_ldlt.yaml"),
      "accuracy-cost: a press a configuration, its scene beside the manifest")
rc, text = tool("make", "ccx-references", "--manifest", f"{gen}/c.jsonl")
rc2, text = tool("run", f"{gen}/c.jsonl", "--out", f"{gen}/c", "--dry-run")
check(rc == 0 and rc2 == 0 and "3 to run" in text and "run_reference.py --model A_pad --element C3D10" in text,
      "ccx-references: A_pad, A, A_coarse in C3D10")
with open(f"{gen}/bad.jsonl", "w") as f:
    f.write('{"name": "x", "command": ["true"]}\n{"name": "y", "command": ["true"]\n')
rc, text = tool("run", f"{gen}/bad.jsonl", "--out", f"{gen}/bad")
check(rc == 2 and f"{gen}/bad.jsonl:2:34: not JSON" in text, "a bad manifest: exit 2, FILE:LINE:COLUMN")

try:
    from distributed import Client
except ImportError:
    print("SKIP: distributed is not importable (apt-get install python3-distributed)")
    sys.exit(1 if failures else 77)

# A case: notes its start (with its parent, the worker's pid), sleeps, then appends its
# completion to the ledger (outside the study's folder, which a retry clears) and writes {out}.
CASE = ("import os,sys,time\n"
        "led,sta,name,sleep_s,out=sys.argv[1:]\n"
        "open(os.path.join(sta,name),'a').write('%d\\n' % os.getppid())\n"
        "time.sleep(float(sleep_s))\n"
        "open(os.path.join(led,name),'a').write('done\\n')\n"
        "open(os.path.join(out,'result.csv'),'w').write('case_name\\n%s\\n' % name)\n")
CRASH = ("import os,sys\n"
         "if not os.path.exists(sys.argv[1]): print('deliberate crash', file=sys.stderr); sys.exit(3)\n")


def case(name, sleep_s=0.4):
    return dict(name=name, command=["{python}", "-c", CASE, LEDGER, STARTS, name, str(sleep_s), "{out}"])


def write_manifest(path, cases):
    with open(path, "w") as f:
        f.write("# test_study.py\n")
        for c in cases:
            f.write(json.dumps(c) + "\n")
        f.write(json.dumps({"gather": {"csv": "result.csv"}}) + "\n")


def lines(folder, name):
    try:
        with open(os.path.join(folder, name)) as f:
            return f.read().split()
    except FileNotFoundError:
        return []


def summary(out):
    with open(os.path.join(out, "summary.csv")) as f:
        return {r["case"]: r for r in csv.DictReader(f)}


def study(manifest, out, scheduler, wait=True):
    cmd = [sys.executable, STUDY, "run", manifest, "--out", out, "--scheduler", scheduler,
           "--sedbridge", args.sedbridge, "--progress-s", "2"]
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if not wait:
        return p
    text = p.communicate(timeout=120)[0]
    print(text)
    return p.returncode, text


def wait_for(what, pred, timeout_s=30):
    t0 = time.time()
    while not pred():
        if time.time() - t0 > timeout_s:
            raise SystemExit(f"test_study: timed out waiting for {what}")
        time.sleep(0.05)


procs = []


def start(cmd, log):
    p = subprocess.Popen(cmd, stdout=open(os.path.join(W, log), "w"), stderr=subprocess.STDOUT)
    procs.append(p)
    return p


try:
    sched_file = os.path.join(W, "scheduler.json")
    start([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", "0",
           "--no-dashboard", "--scheduler-file", sched_file], "scheduler.log")
    wait_for("the scheduler file", lambda: os.path.exists(sched_file))
    time.sleep(0.2)
    address = json.load(open(sched_file))["address"]
    workers = {}
    for name in ("wA", "wB"):
        workers[name] = start([sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads", "1",
                               "--no-nanny", "--name", name, "--host", "127.0.0.1", "--no-dashboard",
                               "--local-directory", os.path.join(W, name)], f"{name}.log")
    with Client(address, timeout="30s") as c:
        c.wait_for_workers(2, timeout=30)
    print(f"scheduler {address}, workers wA (pid {workers['wA'].pid}) and wB (pid {workers['wB'].pid})")

    # 1. Twenty cases, wA killed while it runs one.
    m1, out1 = os.path.join(W, "m1.jsonl"), os.path.join(W, "out1")
    names = [f"c{i:02d}" for i in range(17)]
    write_manifest(m1, [case(n) for n in names]
                   + [dict(name="crash", command=["{python}", "-c", CRASH, FLAG]),
                      dict(name="hang", command=["sleep", "60"], timeout_s=2),
                      dict(name="binary", command=["{sedbridge}", "--help"])])
    p = study(m1, out1, address, wait=False)
    a_pid = str(workers["wA"].pid)

    def wA_mid_case():
        started = [n for n in names if a_pid in lines(STARTS, n)]
        busy = [n for n in started if not lines(LEDGER, n)]
        return len(os.listdir(LEDGER)) >= 3 and busy

    wait_for("wA in the middle of a case", wA_mid_case)
    workers["wA"].send_signal(signal.SIGKILL)
    time.sleep(0.2)
    # Started on wA and not completed once wA is gone: killed with it.
    victims = [n for n in names if a_pid in lines(STARTS, n) and not lines(LEDGER, n)]
    print(f"killed wA while it ran {victims}")
    text = p.communicate(timeout=120)[0]
    print(text)
    s = summary(out1)
    check(p.returncode == 1, f"exit 1 with a failed case (got {p.returncode})")
    check(all(s[n]["status"] == "ok" for n in names + ["binary"]), "the 18 good cases finished")
    check(all(lines(LEDGER, n) == ["done"] for n in names), "each completed exactly once (ledger)")
    check(all(open(os.path.join(out1, "cases", n, "result.csv")).read() == f"case_name\n{n}\n" for n in names),
          "each case's output file in DIR/cases/NAME")
    with open(os.path.join(out1, "results.csv")) as f:
        check(sorted(r["study_case"] for r in csv.DictReader(f)) == names, "results.csv: one row a good case")
    check(len(victims) == 1 and len(lines(STARTS, victims[0])) == 2 and s[victims[0]]["worker"] == "wB",
          f"{victims}: started on wA, killed with it, run again once on wB")
    check(s["crash"]["status"] == "failed" and s["crash"]["rc"] == "3", "the crash: failed, exit status 3")
    check("FAILED crash: exit status 3" in text and "| deliberate crash" in text, "the crash's stderr tail reported")
    check(s["hang"]["status"] == "timeout" and "FAILED hang: timed out after 2 s" in text, "the hang: timed out")
    check("18 of 20 cases finished, 2 failed, 0 not run" in text, "the count")

    # 2. The rerun runs the two failed cases only; the fixed crash now finishes.
    open(FLAG, "w").close()
    rc, text = study(m1, out1, address)
    # The crash's command names the flag file, which exists now: its key changed.
    check("18 finished earlier (skipped), 2 to run (1 failed earlier, 1 changed since)" in text, "rerun: 2 to run")
    s = summary(out1)
    check(s["crash"]["status"] == "ok" and s["hang"]["status"] == "timeout" and rc == 1, "rerun: crash ok, hang not")
    check(all(lines(LEDGER, n) == ["done"] for n in names), "rerun: no good case ran again")

    # 3. An interrupted study resumed runs only what it had not recorded.
    m2, out2 = os.path.join(W, "m2.jsonl"), os.path.join(W, "out2")
    names2 = [f"r{i:02d}" for i in range(10)]
    write_manifest(m2, [case(n, 0.4) for n in names2])
    p = study(m2, out2, address, wait=False)
    wait_for("3 cases of the second study", lambda: sum(bool(lines(LEDGER, n)) for n in names2) >= 3)
    time.sleep(0.1)
    p.send_signal(signal.SIGINT)
    text = p.communicate(timeout=60)[0]
    print(text)
    check(p.returncode == 130 and "study: interrupted" in text, f"interrupted: exit 130 (got {p.returncode})")
    time.sleep(1.5)  # the case wB was running finishes and records itself
    recorded = [n for n in names2 if os.path.exists(os.path.join(out2, "logs", n + ".json"))]
    check(3 <= len(recorded) < 10, f"{len(recorded)} recorded before the interrupt")
    rc, text = study(m2, out2, address)
    m = re.search(r"(\d+) finished earlier \(skipped\), (\d+) to run", text)
    check(rc == 0 and m and int(m.group(1)) == len(recorded) and int(m.group(2)) == 10 - len(recorded),
          "resume: runs only the unrecorded cases")
    check(all(summary(out2)[n]["status"] == "ok" for n in names2), "resume: all 10 finished")
    check(all(len(lines(STARTS, n)) == 1 and lines(LEDGER, n) == ["done"] for n in names2),
          "resume: every case started and completed once")
    rc, text = study(m2, out2, address)
    check(rc == 0 and "10 finished earlier (skipped), 0 to run" in text, "a finished study reruns nothing")
finally:
    for p in procs:
        if p.poll() is None:
            p.terminate()
    for p in procs:
        try:
            p.wait(timeout=10)
        except subprocess.TimeoutExpired:
            p.kill()

if failures:
    print(f"{len(failures)} check(s) failed")
    sys.exit(1)
print("all checks passed")
