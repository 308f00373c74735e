#!/bin/sh
# Builds the libFuzzer targets of tests/fuzz with clang in BUILD_DIR and runs each on a copy
# of its seed corpus, for SECONDS or RUNS executions (0 = no limit of that kind). Prints each
# target's executions; fails on any crash, sanitizer report, leak or timeout. Exit 77 =
# skipped (no clang / libFuzzer).
#   run_fuzzers.sh SOURCE_DIR BUILD_DIR SECONDS [RUNS]
#   short (ctest fuzz_short):  run_fuzzers.sh . build/fuzz 10
#   long (>= 1 M each):        run_fuzzers.sh . build-fuzz2 0 1000000
set -eu
src=$1 build=$2 seconds=$3 runs=${4:-0}
cxx=$(command -v clang++-14 || command -v clang++ || true)
cc=$(command -v clang-14 || command -v clang || true)
if [ -z "$cxx" ] || [ -z "$cc" ]; then
  echo "SKIP: clang not installed (Debian: apt-get install clang libclang-rt-dev)"
  exit 77
fi
mkdir -p "$build"
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$src/tests/fuzz" -B "$build" -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_C_COMPILER="$cc" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo > "$build.configure.log" 2>&1 || {
      cat "$build.configure.log"
      if grep -q "fsanitize=fuzzer" "$build.configure.log"; then echo "SKIP: no libFuzzer runtime"; exit 77; fi
      exit 1
    }
fi
targets="yaml_configs msh lcm_decode limiter_driver candump_line frame_decoder"
cmake --build "$build" -j2 --target $(for t in $targets; do printf 'fuzz_%s ' "$t"; done)
rm -f "$build"/crash-* "$build"/leak-* "$build"/timeout-* "$build"/oom-*
for target in $targets; do
  corpus="$build/corpus_$target"
  mkdir -p "$corpus"
  cp "$src/tests/fuzz/corpus/$target/"* "$corpus/" 2>/dev/null || true
  echo "== fuzz_$target (${seconds}s, ${runs} runs; 0 = unlimited)"
  # -rss_limit_mb / -malloc_limit_mb: an input that allocates without bound is a failure.
  limits="-max_total_time=$seconds"
  [ "$runs" -gt 0 ] && limits="$limits -runs=$runs"
  (cd "$build" && "./fuzz_$target" "$corpus" $limits \
      -rss_limit_mb=2048 -malloc_limit_mb=512 -timeout=10 -print_final_stats=1 > "fuzz_$target.log" 2>&1) || true
  grep -E "stat::number_of_executed_units|Done [0-9]+ runs" "$build/fuzz_$target.log" | tail -2
  if ls "$build"/crash-* "$build"/leak-* "$build"/timeout-* "$build"/oom-* > /dev/null 2>&1 ||
     grep -q "ERROR: libFuzzer\|ERROR: AddressSanitizer\|runtime error:" "$build/fuzz_$target.log"; then
    echo "FAIL: fuzz_$target found a failing input:"
    tail -30 "$build/fuzz_$target.log"
    ls "$build"/crash-* "$build"/leak-* "$build"/timeout-* "$build"/oom-* 2>/dev/null || true
    exit 1
  fi
done
echo "fuzzing: no crash, no sanitizer report, no limit violation"
