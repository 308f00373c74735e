#!/bin/sh
# Builds the libFuzzer targets (tests/sensors/fuzz) with clang in BUILD_DIR and runs each
# for SECONDS on a copy of its seed corpus (regression inputs included). Exit 77 = skipped
# (no clang / libFuzzer).
#   run_fuzzers.sh SOURCE_DIR BUILD_DIR SECONDS
set -eu
src=$1 build=$2 seconds=$3
cxx=$(command -v clang++-14 || command -v clang++ || true)
cc=$(command -v clang-14 || command -v clang || true)
if [ -z "$cxx" ] || [ -z "$cc" ]; then
  echo "SKIP: clang not installed (Debian: apt-get install clang libclang-rt-dev)"
  exit 77
fi
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$src/tests/sensors/fuzz" -B "$build" -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_C_COMPILER="$cc" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo > "$build.configure.log" 2>&1 || {
      cat "$build.configure.log"
      if grep -q "fsanitize=fuzzer" "$build.configure.log"; then echo "SKIP: no libFuzzer runtime"; exit 77; fi
      exit 1
    }
fi
cmake --build "$build" -j2 --target fuzz_candump_line fuzz_frame_decoder
rm -f "$build"/crash-* "$build"/leak-* "$build"/timeout-*  # from an earlier run
for target in candump_line frame_decoder; do
  corpus="$build/corpus_$target"
  mkdir -p "$corpus"
  cp "$src/tests/sensors/fuzz/corpus/$target/"* "$corpus/" 2>/dev/null || true
  echo "== fuzz_$target for ${seconds}s"
  (cd "$build" && "./fuzz_$target" "$corpus" -max_total_time="$seconds" -print_final_stats=1 2>&1 | tail -15)
  status=$?
  # tail hides the fuzzer's status: look for crash artifacts instead.
  if ls "$build"/crash-* "$build"/leak-* "$build"/timeout-* > /dev/null 2>&1; then
    echo "FAIL: fuzz_$target found a failing input:"; ls "$build"/crash-* "$build"/leak-* "$build"/timeout-* 2>/dev/null
    exit 1
  fi
  [ $status -eq 0 ] || exit 1
done
echo "fuzzing: no crash, no sanitizer report"
