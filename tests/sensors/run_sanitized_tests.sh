#!/bin/sh
# Configures the project with -fsanitize=address,undefined (SEDBRIDGE_SANITIZE) in BUILD_DIR,
# builds only the sensor tests and runs them once.
#   run_sanitized_tests.sh SOURCE_DIR BUILD_DIR
set -eu
src=$1 build=$2
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$src" -B "$build" -DSEDBRIDGE_SANITIZE=ON -DSEDBRIDGE_BUILD_BENCHMARKS=OFF \
    -DCMAKE_BUILD_TYPE=Debug > "$build.configure.log" 2>&1 || { cat "$build.configure.log"; exit 1; }
fi
cmake --build "$build" -j2 --target sensors_tests
# Less the rig check of the simulated pads (63 pad presses, each a root find over dense
# contact solves: minutes in an unoptimised build, and no parsing or memory path of its own
# that the other tests of those files do not run).
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  "$build/tests/sensors/sensors_tests" --gtest_brief=1 --gtest_filter=-PadRigCheck.RigFittedLayerReproducesThePressesTheOtherPadsMiss
echo "sensors_tests under ASan+UBSan: passed"
