#pragma once
// SEDBRIDGE_HOT_CLONES before a hot raw-pointer loop's function: GCC builds an x86-64-v3
// (AVX2, FMA) clone beside the baseline one and the loader picks the clone the CPU runs.
// (Per-file -mavx2 would mix Eigen's alignment ABI across translation units: never.)
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define SEDBRIDGE_HOT_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define SEDBRIDGE_HOT_CLONES
#endif
