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
