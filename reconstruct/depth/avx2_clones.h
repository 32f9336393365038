#pragma once

// CASUAL3D_AVX2_CLONES before a function definition compiles it twice on
// x86-64 with GCC, for AVX2 and for the baseline, and the loader picks one by
// the CPU (function multi-versioning): its loops run on eight floats at a
// time where the CPU has AVX2. The AVX2 target does not include FMA, so no
// multiply-add is contracted and both versions give bit-identical results.
// Elsewhere it expands to nothing.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__ELF__)
#define CASUAL3D_AVX2_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define CASUAL3D_AVX2_CLONES
#endif
