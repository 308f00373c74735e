#!/usr/bin/env bash
# Thread scaling of the FE engine on this machine (which team sizes help; docs/performance.md):
#   1. the contact FE step (fem_step_benchmark) on B_fine, B_x4 and B for each team size
#      1, 2, 4, 8, 16 (up to the core count) and 0 (the step chooses its team);
#   2. the paper's press on B (`sedbridge press`, 50 quasi-static steps) with
#      OMP_NUM_THREADS = each team size, and unset (the runtime chooses);
#   3. the same FE steps while half the cores run busy loops (threads must not make
#      a step slower on a loaded machine).
# Prints a markdown table at the end and writes DIR/thread_scaling.csv (one row per run),
# DIR/thread_scaling.log (everything the runs printed), DIR/lscpu.txt and, with matplotlib,
# DIR/thread_scaling.png (speed-up against team size: tools/plot_thread_scaling.py).
#
# usage: tools/thread_scaling.sh [BUILD_DIR [OUT_DIR]]      (Release build; defaults build, out/thread_scaling)
# environment:
#   THREADS="1 2 4"   team sizes to run (default: 1 2 4 8 16, those <= the core count, then 0)
#   SECTIONS="steps press load"   which parts to run (default: these three; "traction" adds the
#                     traction step on B_fine and B_x4)
#   LOAD_THREADS="1 2 0"   team sizes for the loaded runs (default: THREADS)
#   DEADLINE_S=300    start no run after this many seconds (the table is still printed)
#   RUN="..."         prefix for every binary (e.g. a carried loader: "lib/ld-linux-x86-64.so.2 --library-path lib")
set -u
BUILD=${1:-build}
DIR=${2:-out/thread_scaling}
RUN=${RUN:-}
SECTIONS=${SECTIONS:-"steps press load"}
mkdir -p "$DIR"
RAW=$(mktemp -d)
LOG="$DIR/thread_scaling.log"
: >"$LOG"
CORES=$(nproc)
if [[ -z "${THREADS:-}" ]]; then
  THREADS=""
  for t in 1 2 4 8 16; do ((t <= 2 || t <= CORES)) && THREADS+="$t "; done
  THREADS+="0"
fi
# Models and scenes come from this checkout, wherever the script is run from.
export SEDBRIDGE_ROOT=${SEDBRIDGE_ROOT:-$(cd "$(dirname "$0")/.." && pwd)}
(lscpu; echo; uptime) >"$DIR/lscpu.txt" 2>&1
# Past DEADLINE_S seconds no new run starts, so the table still gets printed.
out_of_time() { [[ -n ${DEADLINE_S:-} ]] && ((SECONDS > DEADLINE_S)) && say "skipped: past DEADLINE_S=$DEADLINE_S"; }
say() { echo "[$(date -u +%H:%M:%S) load $(cut -d' ' -f1 /proc/loadavg)] $*" | tee -a "$LOG" >&2; }

# One fem_step_benchmark run per (model, case, team): a killed run loses only itself.
step_runs() {  # tag model filter_regex
  local tag=$1 model=$2 filter=$3
  for t in ${TEAMS:-$THREADS}; do
    out_of_time && return
    say "$tag $model $filter team $t"
    SEDBRIDGE_BENCH_MODEL=$model timeout "${STEP_TIMEOUT:-240}" $RUN "$BUILD/tests/bench/fem_step_benchmark" \
      --benchmark_filter="${filter}/${t}/" --benchmark_format=json \
      >"$RAW/${tag}__${model}__${t}.json" 2>>"$LOG" || say "  exit $? (team $t)"
  done
}

steps() {
  for m in B_fine B_x4; do step_runs steps $m 'ContactPressStep/backward_euler/corotational/pcg_warp'; done
  step_runs steps B 'ContactPressStep/backward_euler/corotational/pcg_warp(/cap1)?'
}

traction() {
  for m in B_fine B_x4; do step_runs traction $m 'TractionStep/backward_euler/corotational/pcg_warp'; done
}

press() {
  for t in $THREADS; do
    out_of_time && return
    local env_threads=$t
    [[ $t == 0 ]] && env_threads=""
    say "press B OMP_NUM_THREADS=${env_threads:-unset}"
    local t0=$EPOCHREALTIME
    if [[ -n $env_threads ]]; then
      OMP_NUM_THREADS=$t timeout 240 $RUN "$BUILD/sedbridge" press --scene "$SEDBRIDGE_ROOT/config/scenes/paper_press.yaml" \
        --out "$RAW/press_$t" --no-plots --quiet >>"$LOG" 2>&1
    else
      (unset OMP_NUM_THREADS; timeout 240 $RUN "$BUILD/sedbridge" press --scene "$SEDBRIDGE_ROOT/config/scenes/paper_press.yaml" \
        --out "$RAW/press_$t" --no-plots --quiet >>"$LOG" 2>&1)
    fi
    local rc=$? t1=$EPOCHREALTIME
    echo "press,B,$t,$(awk -v a="$t0" -v b="$t1" 'BEGIN{print b-a}'),$rc" >>"$RAW/press.csv"
  done
}

# The busy loops (and the raw folder) never outlive the script (Ctrl-C, a kill, an error).
HOG_PIDS=()
stop_hogs() {
  ((${#HOG_PIDS[@]})) || return 0
  kill "${HOG_PIDS[@]}" 2>/dev/null
  wait "${HOG_PIDS[@]}" 2>/dev/null
  HOG_PIDS=()
}
trap 'stop_hogs; rm -rf "$RAW"' EXIT
trap 'stop_hogs; exit 130' INT TERM

load() {
  local hogs=$((CORES / 2))
  ((hogs < 1)) && hogs=1
  for _ in $(seq "$hogs"); do (while :; do :; done) & HOG_PIDS+=($!); done
  say "load: $hogs busy loops on $CORES cores"
  TEAMS=${LOAD_THREADS:-$THREADS} STEP_TIMEOUT=60 step_runs load B 'ContactPressStep/backward_euler/corotational/pcg_warp/cap1'
  TEAMS=${LOAD_THREADS:-$THREADS} STEP_TIMEOUT=60 step_runs load B_fine 'ContactPressStep/backward_euler/corotational/pcg_warp'
  stop_hogs
}

for s in $SECTIONS; do
  case $s in
    steps | press | load | traction) ;;
    *) echo "thread_scaling.sh: unknown section '$s' in SECTIONS (steps, press, load, traction)" >&2; exit 2 ;;
  esac
done
for s in $SECTIONS; do say "section $s"; $s; done

# Merge the runs into one CSV and print the table.
python3 - "$RAW" "$DIR/thread_scaling.csv" <<'EOF'
import csv, glob, json, os, sys
raw, out = sys.argv[1], sys.argv[2]
rows = []
for f in sorted(glob.glob(os.path.join(raw, "*.json"))):
    tag, model, team = os.path.basename(f)[:-5].split("__")
    try:
        data = json.load(open(f))
    except Exception:
        continue
    for b in data.get("benchmarks", []):
        rows.append(dict(section=tag, model=model, case=b["name"].split("/iterations")[0], team=int(team),
                         threads=b.get("threads", ""), median_ms=b.get("median_ms", ""), p99_ms=b.get("p99_ms", ""),
                         assembly_ms=b.get("assembly_ms", ""), solve_ms=b.get("solve_ms", ""), sed_ms=b.get("sed_ms", ""),
                         force_N=b.get("force_N", "")))
pf = os.path.join(raw, "press.csv")
if os.path.exists(pf):
    for line in open(pf):
        _, model, team, wall, rc = line.strip().split(",")
        rows.append(dict(section="press", model=model, case="press paper_press.yaml (wall s)" + ("" if rc == "0" else f" rc={rc}"),
                         team=int(team), threads="", median_ms=float(wall) * 1e3, p99_ms="", assembly_ms="", solve_ms="",
                         sed_ms="", force_N=""))
keys = ["section", "model", "case", "team", "threads", "median_ms", "p99_ms", "assembly_ms", "solve_ms", "sed_ms", "force_N"]
with open(out, "w", newline="") as fh:
    w = csv.DictWriter(fh, fieldnames=keys)
    w.writeheader()
    w.writerows(rows)
groups = {}
for r in rows:
    groups.setdefault((r["section"], r["model"], r["case"].rsplit("/", 1)[0] if r["section"] != "press" else r["case"]), {})[r["team"]] = r
teams = sorted({r["team"] for r in rows}, key=lambda t: (t == 0, t))
print("| section | model | case | " + " | ".join(f"team {t}" if t else "chosen" for t in teams) + " |")
print("|---" * (3 + len(teams)) + "|")
for (sec, model, case), by_team in groups.items():
    base = by_team.get(1)
    cells = []
    for t in teams:
        r = by_team.get(t)
        if not r or r["median_ms"] == "":
            cells.append("–")
            continue
        v = float(r["median_ms"])
        cell = f"{v/1e3:.2f} s" if sec == "press" else f"{v:.2f}"
        if base and base["median_ms"] != "" and t != 1:
            cell += f" ({float(base['median_ms'])/v:.2f}×)"
        if sec != "press" and t == 0 and r["threads"] != "":
            cell += f" [{int(r['threads'])}]"
        cells.append(cell)
    print(f"| {sec} | {model} | {case} | " + " | ".join(cells) + " |")
print("(step rows: median ms a step, speed-up over team 1 in brackets; chosen: [team kept]; press: wall s)")
EOF
(cd "$RAW" && tar -czf - *.json press.csv press_*/force_displacement.csv 2>/dev/null) >"$DIR/raw.tar.gz"
# The same as a plot, with the first Python that has matplotlib (Debian's python3-matplotlib
# is /usr/bin/python3's), as sedbridge's own plots look for it.
for py in /usr/bin/python3 python3; do
  if "$py" -c "import matplotlib" 2>/dev/null; then
    "$py" "$(dirname "$0")/plot_thread_scaling.py" "$DIR/thread_scaling.csv" --out "$DIR/thread_scaling.png" \
      --title "$(hostname), $(nproc) cores, $(date -u +'%Y-%m-%d %H:%M UTC')"
    break
  fi
done
rm -rf "$RAW"
