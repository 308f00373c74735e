#!/usr/bin/python3
"""Run a study (a manifest of independent cases) on Dask distributed (docs/lab-tools.md#studies).

usage: study.py run MANIFEST --out DIR [--scheduler tcp://HOST:8786 | --scheduler-file F | --workers N]
                    [--sedbridge build/sedbridge] [--timeout-s 3600] [--retries 0] [--case-threads 1]
                    [--progress-s 30] [--dry-run]
       study.py make fidelity-random|accuracy-cost|ccx-references ... --manifest FILE   (tools/study_manifests.py)

MANIFEST holds one JSON object a line (blank lines and lines starting with # are skipped):
  {"name": "seed_1", "command": ["{sedbridge}", "fidelity", "--synthetic", "--random", "30", "--seed", "1",
   "--no-plots", "--out", "{out}"], "inputs": [], "timeout_s": 600, "retries": 0, "env": {}}
and at most one gather line, run here after the cases:
  {"gather": {"csv": "fidelity.csv", "command": ["{python}", "{repo}/tools/fidelity_envelope.py", "{cases_ok}"]}}
Placeholders: {sedbridge} (--sedbridge), {python} (the Python that runs the case), {repo} (this
repository), {manifest} (the manifest's folder), {out} (the case's output folder DIR/cases/NAME),
{study} (DIR, gather only), {cases_ok} (gather only: one argument per case that finished).
Commands run in the repository root with OMP_NUM_THREADS=--case-threads unless "env" says otherwise.

A case's key is the SHA-256 of its command as written, its env, and the contents of every file its
command names (the binary, a script, a scene) and of its "inputs". DIR/logs/NAME.json records each
finished case with its key: a rerun skips the cases finished with the same key and runs the failed,
the missing and the changed ones. DIR/logs/NAME.{stdout,stderr}.txt hold the output of the last
attempt, DIR/summary.csv one row a case, DIR/results.csv the gather CSV of every finished case.

Why Python: Dask's client API is Python; the cases themselves are the project's commands.
Exits 0 when every case finished, 1 when some failed, 2 on a bad manifest, 130 when interrupted.
"""
import argparse
import csv
import fcntl
import hashlib
import json
import os
import re
import shutil
import signal
import sys
import time
import uuid

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.abspath(os.path.join(HERE, ".."))
NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.+-]*$")
CASE_FIELDS = {"name", "command", "inputs", "timeout_s", "retries", "env"}
SUMMARY_FIELDS = ["case", "status", "rc", "wall_s", "attempts", "worker", "host", "finished_utc", "key", "error"]


class ManifestError(Exception):
    pass


def read_manifest(path):
    """The cases and the gather step of a manifest; ManifestError 'path:line:column: what'."""
    cases, gather, names = [], None, set()
    with open(path) as f:
        for lineno, line in enumerate(f, 1):
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            where = f"{path}:{lineno}"
            try:
                obj = json.loads(line.rstrip("\r\n"))
            except json.JSONDecodeError as e:
                raise ManifestError(f"{where}:{e.colno}: not JSON: {e.msg}")
            if not isinstance(obj, dict):
                raise ManifestError(f"{where}:1: a line must be a JSON object")
            if "gather" in obj:
                if gather is not None:
                    raise ManifestError(f"{where}:1: a second gather line")
                gather = check_gather(obj["gather"], where)
                continue
            cases.append(check_case(obj, where, names))
    if not cases:
        raise ManifestError(f"{path}:1:1: no cases")
    return cases, gather


def check_case(obj, where, names):
    unknown = set(obj) - CASE_FIELDS
    if unknown:
        raise ManifestError(f"{where}:1: unknown field(s) {', '.join(sorted(unknown))}")
    name = obj.get("name")
    if not isinstance(name, str) or not NAME_RE.match(name):
        raise ManifestError(f"{where}:1: \"name\" must be letters, digits, _ . + - (got {name!r})")
    if name in names:
        raise ManifestError(f"{where}:1: case {name} twice")
    names.add(name)
    cmd = obj.get("command")
    if not isinstance(cmd, list) or not cmd or not all(isinstance(c, str) for c in cmd):
        raise ManifestError(f"{where}:1: \"command\" must be a non-empty list of strings")
    inputs = obj.get("inputs", [])
    if not isinstance(inputs, list) or not all(isinstance(i, str) for i in inputs):
        raise ManifestError(f"{where}:1: \"inputs\" must be a list of paths")
    env = obj.get("env", {})
    if not isinstance(env, dict) or not all(isinstance(v, str) for v in env.values()):
        raise ManifestError(f"{where}:1: \"env\" must map names to strings")
    for k in ("timeout_s", "retries"):
        if k in obj and (not isinstance(obj[k], (int, float)) or obj[k] < 0):
            raise ManifestError(f"{where}:1: \"{k}\" must be a number >= 0")
    return dict(obj, inputs=inputs, env=env, where=where)


def check_gather(g, where):
    if not isinstance(g, dict) or set(g) - {"csv", "command"}:
        raise ManifestError(f"{where}:1: \"gather\" takes {{\"csv\": FILE, \"command\": [...]}}")
    if "command" in g and (not isinstance(g["command"], list) or not all(isinstance(c, str) for c in g["command"])):
        raise ManifestError(f"{where}:1: the gather \"command\" must be a list of strings")
    return g


def expand(text, ctx):
    """Replaces the {placeholders} that ctx knows; {python} is left for the worker."""
    for k, v in ctx.items():
        text = text.replace("{" + k + "}", v)
    return text


_hash_cache = {}


def file_sha256(path):
    st = os.stat(path)
    memo = (path, st.st_size, st.st_mtime_ns)
    if memo not in _hash_cache:
        h = hashlib.sha256()
        with open(path, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
        _hash_cache[memo] = h.hexdigest()
    return _hash_cache[memo]


def case_key(case, ctx, manifest_dir):
    """SHA-256 of the command as written, its env, and every file it names or lists as input."""
    files = {}
    for arg in case["command"]:
        p = expand(arg, ctx)
        if os.path.isfile(p):
            files[arg] = file_sha256(p)
    for inp in case["inputs"]:
        p = os.path.join(manifest_dir, expand(inp, ctx))
        if not os.path.isfile(p):
            raise ManifestError(f"{case['where']}:1: input {p}: no such file")
        files[inp] = file_sha256(p)
    if "{python}" in case["command"]:
        files["{python}"] = "python%d.%d" % sys.version_info[:2]
    blob = json.dumps(dict(command=case["command"], env=case["env"], files=files), sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()


def run_case(spec):
    """On a worker: runs one case (with its retries) and returns its record. Self-contained: Dask
    ships it to workers that need not have this file."""
    import json
    import os
    import shutil
    import signal
    import socket
    import subprocess
    import sys
    import time
    # Dask reruns a task whose worker died, also after it finished (its result was lost with
    # the worker): a case its record says finished is not run again.
    try:
        with open(spec["record"]) as f:
            old = json.load(f)
        if old.get("key") == spec["key"] and old.get("status") == "ok":
            return dict(old, reused=True)
    except (OSError, ValueError):
        pass
    argv = [a.replace("{python}", sys.executable) for a in spec["argv"]]
    # A worker that dies takes its case with it (the scheduler then runs the case elsewhere):
    # without this the orphan would finish too and the case would complete twice.
    if shutil.which("setpriv"):
        argv = ["setpriv", "--pdeathsig", "KILL", "--"] + argv
    env = dict(os.environ, **spec["env"])
    worker = ""
    try:
        from distributed import get_worker
        worker = str(get_worker().name)
    except Exception:  # noqa: BLE001 (not on a worker, e.g. a test calling it directly)
        pass
    rec = dict(status="failed", rc=None, wall_s=0.0, attempts=0, worker=worker, host=socket.gethostname(), error="")
    for attempt in range(1, int(spec["retries"]) + 2):
        rec["attempts"] = attempt
        shutil.rmtree(spec["out"], ignore_errors=True)
        os.makedirs(spec["out"])
        t0 = time.time()
        try:
            with open(spec["stdout"], "wb") as so, open(spec["stderr"], "wb") as se:
                p = subprocess.Popen(argv, cwd=spec["cwd"], env=env, stdout=so, stderr=se, stdin=subprocess.DEVNULL,
                                     start_new_session=True)
                try:
                    rc = p.wait(timeout=spec["timeout_s"] or None)
                    rec.update(status="ok" if rc == 0 else "failed", rc=rc,
                               error="" if rc == 0 else f"exit status {rc}" if rc > 0 else f"killed by signal {-rc}")
                except subprocess.TimeoutExpired:
                    os.killpg(p.pid, signal.SIGKILL)  # its children too
                    p.wait()
                    rec.update(status="timeout", rc=None, error=f"timed out after {spec['timeout_s']:g} s")
        except OSError as e:
            rec.update(status="failed", rc=None, error=f"cannot run {argv[0]}: {e}")
        rec["wall_s"] = round(time.time() - t0, 3)
        if rec["status"] == "ok":
            break
    rec.update(case=spec["name"], key=spec["key"], finished_utc=time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()))
    tmp = f"{spec['record']}.tmp.{socket.gethostname()}.{os.getpid()}"
    with open(tmp, "w") as f:
        json.dump(rec, f, indent=1)
    os.replace(tmp, spec["record"])  # recorded: finished even if this worker dies now
    return rec


def stderr_tail(path, lines=12):
    try:
        with open(path, errors="replace") as f:
            return [l.rstrip("\n") for l in f.readlines()[-lines:]]
    except OSError:
        return []


def write_json_atomic(path, obj):
    tmp = f"{path}.tmp{os.getpid()}"
    with open(tmp, "w") as f:
        json.dump(obj, f, indent=1)
    os.replace(tmp, path)


def earlier_record(log_dir, name):
    try:
        with open(os.path.join(log_dir, name + ".json")) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def connect(a):
    """(client, cluster or None): the given scheduler, or a local cluster of --workers processes."""
    from distributed import Client, LocalCluster
    if a.scheduler:
        return Client(a.scheduler, timeout="30s"), None
    if a.scheduler_file:
        return Client(scheduler_file=a.scheduler_file, timeout="30s"), None
    import logging
    n = a.workers or os.cpu_count() or 1
    cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                           silence_logs=logging.ERROR)
    return Client(cluster), cluster


class Progress:
    """The terminal line: done / running / failed / left and the time left at this run's pace."""

    def __init__(self, total, skipped, client):
        self.total, self.skipped, self.client = total, skipped, client
        self.ok = self.failed = 0
        self.t0 = time.time()
        self.last_print = 0.0

    def line(self, left, last=""):
        try:
            threads = sum(self.client.nthreads().values())
        except Exception:  # noqa: BLE001 (scheduler gone: the next wait says so)
            threads = 0
        elapsed = time.time() - self.t0
        ran = self.ok + self.failed
        eta = f" · ~{elapsed / ran * left:.0f} s left" if ran and left else ""
        done = self.skipped + self.ok
        print(f"study: [{done + self.failed}/{self.total}] done {done} · running {min(left, threads)} · "
              f"failed {self.failed} · left {left} · {elapsed:.0f} s{eta}{last}", flush=True)
        self.last_print = time.time()


def run_study(a):
    manifest = os.path.abspath(a.manifest)
    try:
        cases, gather = read_manifest(manifest)
    except (ManifestError, OSError) as e:
        print(f"study: {e}", file=sys.stderr)
        return 2
    out = os.path.abspath(a.out)
    log_dir, cases_dir = os.path.join(out, "logs"), os.path.join(out, "cases")
    os.makedirs(log_dir, exist_ok=True)
    os.makedirs(cases_dir, exist_ok=True)
    lock = open(os.path.join(out, "study.lock"), "w")
    try:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        print(f"study: {out} is in use by another study.py", file=sys.stderr)
        return 2
    ctx = dict(sedbridge=os.path.abspath(a.sedbridge), repo=REPO, manifest=os.path.dirname(manifest))
    records, todo, changed, refail = {}, [], 0, 0
    for c in cases:
        try:
            key = case_key(c, ctx, ctx["manifest"])
        except ManifestError as e:
            print(f"study: {e}", file=sys.stderr)
            return 2
        rec = earlier_record(log_dir, c["name"])
        if rec and rec.get("key") == key and rec.get("status") == "ok":
            records[c["name"]] = rec
            continue
        changed += bool(rec and rec.get("key") != key)
        refail += bool(rec and rec.get("key") == key)
        todo.append((c, key))
    print(f"study: {len(cases)} cases in {manifest}; {len(records)} finished earlier (skipped), {len(todo)} to run "
          f"({refail} failed earlier, {changed} changed since)", flush=True)
    if a.dry_run:
        for c, _ in todo:
            cctx = dict(ctx, out=os.path.join(cases_dir, c["name"]), python=sys.executable)
            print(f"  {c['name']}: " + " ".join(expand(x, cctx) for x in c["command"]))
        return 0
    rc = 0
    try:
        if todo:
            rc = dispatch(a, todo, ctx, log_dir, cases_dir, records, len(cases))
    except KeyboardInterrupt:  # while the cluster started or stopped
        print("study: interrupted; the same command resumes the study", file=sys.stderr, flush=True)
        rc = 130
    write_summary(cases, records, out)
    report_failures(cases, records, log_dir)
    if rc == 130:
        return rc
    gather_results(gather, cases, records, ctx, out, cases_dir)
    return 0 if all(records.get(c["name"], {}).get("status") == "ok" for c in cases) else 1


def dispatch(a, todo, ctx, log_dir, cases_dir, records, total):
    """Submits the cases, records each as it comes back; 130 when interrupted."""
    from distributed import as_completed
    client, cluster = connect(a)
    where = a.scheduler or a.scheduler_file or f"local cluster of {len(client.nthreads())} workers"
    print(f"study: running on {where} ({sum(client.nthreads().values())} threads)", flush=True)
    futures = {}
    for c, key in todo:
        name = c["name"]
        spec = dict(name=name, key=key, record=os.path.join(log_dir, name + ".json"),
                    argv=[expand(x, dict(ctx, out=os.path.join(cases_dir, name))) for x in c["command"]],
                    env=dict({"OMP_NUM_THREADS": str(a.case_threads)}, **c["env"]), cwd=REPO,
                    out=os.path.join(cases_dir, name), stdout=os.path.join(log_dir, name + ".stdout.txt"),
                    stderr=os.path.join(log_dir, name + ".stderr.txt"),
                    timeout_s=float(c.get("timeout_s", a.timeout_s)), retries=int(c.get("retries", a.retries)))
        fut = client.submit(run_case, spec, key=f"study-{name}-{uuid.uuid4().hex[:8]}", pure=False)
        futures[fut.key] = (fut, name, key)
    progress = Progress(total, len(records), client)
    progress.line(len(futures))
    ac = as_completed([f for f, _, _ in futures.values()])
    left = len(futures)
    try:
        while left:
            batch = ac.next_batch(block=False)
            if not batch:
                time.sleep(0.2)
                if time.time() - progress.last_print >= a.progress_s:
                    progress.line(left)
                continue
            for done in batch:
                fut, name, key = futures.pop(done.key)
                try:
                    rec = fut.result()
                except Exception as e:  # noqa: BLE001 (KilledWorker: the workers running it kept dying)
                    rec = dict(case=name, key=key, status="failed", rc=None, wall_s=0.0, attempts=0, worker="",
                               host="", error=f"{type(e).__name__}: {e}",
                               finished_utc=time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()))
                    write_json_atomic(os.path.join(log_dir, name + ".json"), rec)
                # Held, a finished case's future would make Dask rerun it if its worker died.
                fut.release()
                records[name] = rec
                left -= 1
                if rec["status"] == "ok":
                    progress.ok += 1
                else:
                    progress.failed += 1
                progress.line(left, f" · {name} {rec['status']} {rec['wall_s']:.1f} s"
                                    + (f", worker {rec['worker']}" if rec["worker"] else "")
                                    + (" (recorded before its worker died)" if rec.get("reused") else ""))
        return 0
    except KeyboardInterrupt:
        print(f"study: interrupted with {left} cases not back; the same command resumes the study "
              "(a case still running on a worker records itself when it finishes)",
              file=sys.stderr, flush=True)
        client.cancel([f for f, _, _ in futures.values()])
        return 130
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def write_summary(cases, records, out):
    with open(os.path.join(out, "summary.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=SUMMARY_FIELDS, extrasaction="ignore")
        w.writeheader()
        for c in cases:
            rec = records.get(c["name"], dict(status="not_run"))
            w.writerow(dict(rec, case=c["name"]))


def report_failures(cases, records, log_dir):
    bad = [c["name"] for c in cases if records.get(c["name"], {}).get("status") not in ("ok", None)]
    for name in bad:
        rec = records[name]
        print(f"study: FAILED {name}: {rec['error']} (attempts {rec['attempts']}, {rec['wall_s']:.1f} s"
              + (f", worker {rec['worker']}" if rec["worker"] else "") + f"); stderr tail ({log_dir}/{name}.stderr.txt):",
              file=sys.stderr)
        for l in stderr_tail(os.path.join(log_dir, name + ".stderr.txt")):
            print("  | " + l, file=sys.stderr)
    n_ok = sum(1 for c in cases if records.get(c["name"], {}).get("status") == "ok")
    print(f"study: {n_ok} of {len(cases)} cases finished, {len(bad)} failed, {len(cases) - n_ok - len(bad)} not run",
          flush=True)


def gather_results(gather, cases, records, ctx, out, cases_dir):
    """results.csv (the named CSV of every finished case, a study_case column first) and the
    manifest's gather command over the finished cases."""
    if not gather:
        return
    ok = [c["name"] for c in cases if records.get(c["name"], {}).get("status") == "ok"]
    if not ok:
        print("study: gather skipped: no case finished")
        return
    if gather.get("csv"):
        path, header, n, without = os.path.join(out, "results.csv"), None, 0, []
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            for name in ok:
                src = os.path.join(cases_dir, name, gather["csv"])
                if not os.path.isfile(src):
                    without.append(name)
                    continue
                with open(src, newline="") as g:
                    rows = list(csv.reader(g))
                if not rows:
                    continue
                if header is None:
                    header = rows[0]
                    w.writerow(["study_case"] + header)
                elif rows[0] != header:
                    print(f"study: {src}: other columns than the first case's (not in results.csv)", file=sys.stderr)
                    continue
                w.writerows([name] + r for r in rows[1:])
                n += len(rows) - 1
        print(f"study: wrote {path} ({n} rows from {len(ok) - len(without)} cases)"
              + (f"; without {gather['csv']}: {', '.join(without)}" if without else ""))
    if gather.get("command"):
        import subprocess
        gctx = dict(ctx, study=out, python=sys.executable)
        argv = []
        for x in gather["command"]:
            argv += [os.path.join(cases_dir, n) for n in ok] if x == "{cases_ok}" else [expand(x, gctx)]
        print(f"study: gather over {len(ok)} of {len(cases)} cases: {' '.join(argv[:6])}{' ...' if len(argv) > 6 else ''}",
              flush=True)
        with open(os.path.join(out, "gather.txt"), "w") as log:
            r = subprocess.run(argv, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            log.write(r.stdout)
        sys.stdout.write(r.stdout)
        if r.returncode != 0:
            print(f"study: the gather command exited with {r.returncode} (its output: {out}/gather.txt)",
                  file=sys.stderr)


def default_sedbridge():
    """build/sedbridge in a checkout, P/bin/sedbridge in an installed P/share/sedbridge/tools."""
    for p in (os.path.join(REPO, "build", "sedbridge"), os.path.join(REPO, "..", "..", "bin", "sedbridge")):
        if os.path.isfile(p):
            return os.path.abspath(p)
    return shutil.which("sedbridge") or os.path.join(REPO, "build", "sedbridge")


def interrupt(signum, frame):
    raise KeyboardInterrupt


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["make"]:
        sys.path.insert(0, HERE)
        import study_manifests
        return study_manifests.main(argv[1:])
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run (or resume) the study of a manifest")
    r.add_argument("manifest")
    r.add_argument("--out", required=True, help="the study's folder: cases/, logs/, summary.csv, results.csv")
    r.add_argument("--scheduler", help="a running Dask scheduler, tcp://HOST:8786 (default: a local cluster)")
    r.add_argument("--scheduler-file", help="the scheduler's --scheduler-file (Slurm: tools/study_slurm.sbatch)")
    r.add_argument("--workers", type=int, default=0, help="local cluster: worker processes (default: one a core)")
    r.add_argument("--sedbridge", default=default_sedbridge(), help="what {sedbridge} names (default: build/sedbridge)")
    r.add_argument("--timeout-s", type=float, default=3600.0, help="per case, unless its line says (0: none)")
    r.add_argument("--retries", type=int, default=0, help="reruns of a failed case, unless its line says")
    r.add_argument("--case-threads", type=int, default=1, help="OMP_NUM_THREADS of each case")
    r.add_argument("--dry-run", action="store_true", help="list the cases to run, run nothing")
    r.add_argument("--progress-s", type=float, default=30.0, help="a progress line at least this often")
    sub.add_parser("make", help="write a manifest (tools/study_manifests.py; `study.py make -h`)")
    a = ap.parse_args(argv)
    # Slurm and kill send SIGTERM: stop like Ctrl-C (results so far are kept).
    signal.signal(signal.SIGTERM, interrupt)
    return run_study(a)


if __name__ == "__main__":
    sys.exit(main())
