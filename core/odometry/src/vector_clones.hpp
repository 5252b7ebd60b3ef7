#pragma once
// NIDEVO_VECTOR_CLONES before a loop kernel compiles it twice, for AVX2 and for the x86-64
// baseline (SSE2), and picks one when the program loads: the portable build keeps running on
// any x86-64 while the kernels take eight floats at a time where the CPU can. Without FMA
// (not enabled here) both clones round every operation alike: the results are the same bits.
// ThreadSanitizer's runtime is not up yet when the loader picks a clone (the program crashes
// before main), so a TSan build has the baseline code only.
#if defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define NIDEVO_NO_VECTOR_CLONES
#endif
#endif
#if defined(__SANITIZE_THREAD__)
#define NIDEVO_NO_VECTOR_CLONES
#endif
#if defined(__x86_64__) && defined(__has_attribute) && !defined(NIDEVO_NO_VECTOR_CLONES)
#if __has_attribute(target_clones)
#define NIDEVO_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#endif
#endif
#ifndef NIDEVO_VECTOR_CLONES
#define NIDEVO_VECTOR_CLONES
#endif
