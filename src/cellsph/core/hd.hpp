#pragma once
// One macro marks code that runs on both the CPU and a CUDA device. Host-only translation
// units see an empty macro, so no public header depends on CUDA.
#if defined(__CUDACC__)
#define CELLSPH_HD __host__ __device__
#else
#define CELLSPH_HD
#endif

// Forces inlining of a small function called in a pair loop: the passes' bodies are large, and GCC
// otherwise leaves some pair functions out of line, where each call makes the loop reload every array
// pointer and parameter of the pass from memory.
#if defined(__CUDACC__)
#define CELLSPH_INLINE __forceinline__
#elif defined(__GNUC__)
#define CELLSPH_INLINE inline __attribute__((always_inline))
#else
#define CELLSPH_INLINE inline
#endif

// Before a pair loop that sums in row order (the sweeps' rates and kicks): keeps the host compiler from
// vectorizing it. GCC 12 otherwise takes two pairs an iteration in an in-order (strict IEEE) reduction,
// with about ten shuffles a pair that cost more than they save: one pair an iteration is 10-15% faster
// (docs/benchmarks.md, "What do the compiler and the build options change?"). The sums, their order and
// the bits are the same either way. The loop must be in OpenMP's canonical form (an integer index).
#if defined(__CUDA_ARCH__)  // empty in device code
#define CELLSPH_SCALAR_LOOP
#elif defined(__clang__)
#define CELLSPH_SCALAR_LOOP _Pragma("clang loop vectorize(disable) interleave(disable)")
#elif defined(__GNUC__) && __GNUC__ >= 14
#define CELLSPH_SCALAR_LOOP _Pragma("GCC novector")
#elif defined(__GNUC__) && defined(_OPENMP)
// No iteration runs beside another (safelen 1), one lane (simdlen 1): GCC 12 then leaves the loop scalar.
#define CELLSPH_SCALAR_LOOP _Pragma("omp simd safelen(1) simdlen(1)")
#else
#define CELLSPH_SCALAR_LOOP
#endif
