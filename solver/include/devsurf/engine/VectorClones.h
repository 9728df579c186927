#pragma once

/// DEVSURF_VECTOR_CLONES: compiles a hot loop twice, for AVX2 and for the baseline x86-64 (SSE2),
/// and picks one when the program loads (GCC's `target_clones`, an ifunc resolved from the
/// CPU's features). The build itself targets the baseline so that one binary runs everywhere; the
/// accumulation of JᵀJ and the elimination of the normals are element-wise loops over rows of 12–36
/// entries that AVX2 runs four lanes wide (issue 17: the non-factorization part of an iteration).
///
/// FMA is deliberately not enabled: without contraction an AVX2 loop rounds exactly as the SSE2
/// one does (the loops are element-wise, the compiler does not reorder sums without fast-math), so
/// every machine computes the same iterates — nodes of one cluster, or CI and a laptop, agree to
/// the last bit.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__) && \
    !defined(__SANITIZE_THREAD__) && !defined(DEVSURF_NO_VECTOR_CLONES)
// GCC only: Clang 14 declares the dispatcher of a cloned member template but never defines its
// resolver (the fuzz build, which is Clang, would not link), and the sanitizer builds keep one
// code path.
#define DEVSURF_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define DEVSURF_VECTOR_CLONES
#endif
