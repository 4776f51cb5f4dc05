#pragma once
// One macro marks code that runs on both the CPU and a CUDA device. Host-only translation
// units see an empty macro, so no public header depends on CUDA.
#if defined(__CUDACC__)
#define CELLSPH_HD __host__ __device__
#else
#define CELLSPH_HD
#endif
