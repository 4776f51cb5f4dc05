#pragma once
// The CUDA pass driver: the overloads of run_pass, reduce_max, reduce_sum and first_where for CUDA index sets
// (solver/device/device_driver.hpp declares the sets; the CPU driver is solver/pass_driver.hpp), and
// DeviceOps<CudaSpace> (CUB's radix sort and scan). Each pass is the CPU's functor, copied by value into
// the kernel (a pass holds a ParticleView of device pointers and plain parameters). Seen only by nvcc.
//
// NOT RUN YET: compiled in CI; scripts/gpu_check.sh runs it when a GPU is lent (docs/gpu.md).
#include <cuda_runtime.h>
#include <cuda/std/functional>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cub/block/block_reduce.cuh>
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>
#include <cub/version.cuh>
#include <vector>

#include "cellsph/cuda/cuda_check.cuh"
#include "cellsph/solver/device/device_driver.hpp"
#include "cellsph/solver/device/memory_space.hpp"

// CUDA 13's CUB (CCCL, under include/cccl); Debian's libcub-dev / libthrust-dev (1.17) in /usr/include
// would be found first by a plain -I and lacks the API used here (docs/gpu.md).
static_assert(CUB_VERSION >= 200000, "an old CUB (Debian's libcub-dev?) was included instead of CUDA's CCCL");

namespace cellsph {

namespace cuda_detail {

inline constexpr int kBlock = 256;
inline constexpr std::size_t kMaxReduceBlocks = 1024;

inline unsigned blocks_for(std::size_t n, std::size_t cap = 65535) {
  return static_cast<unsigned>(std::min<std::size_t>((n + kBlock - 1) / kBlock, cap));
}

inline void check_launch(const char* what) {
  const cudaError_t err = cudaGetLastError();
  if (err != cudaSuccess) cuda_failed(err, what, __FILE__, __LINE__);
}

template <class Pass>
__global__ void __launch_bounds__(kBlock) set_kernel(const std::uint32_t* idx, std::size_t n, Pass pass) {
  const std::size_t stride = std::size_t{gridDim.x} * blockDim.x;
  for (std::size_t k = std::size_t{blockIdx.x} * blockDim.x + threadIdx.x; k < n; k += stride)
    pass(static_cast<std::size_t>(idx[k]));
}

template <class Pass>
__global__ void __launch_bounds__(kBlock) range_kernel(std::size_t n, Pass pass) {
  const std::size_t stride = std::size_t{gridDim.x} * blockDim.x;
  for (std::size_t k = std::size_t{blockIdx.x} * blockDim.x + threadIdx.x; k < n; k += stride) pass(k);
}

template <class Result>
struct MaxOf {
  __device__ Result operator()(const Result& a, const Result& b) const { return Result::max_of(a, b); }
};

// Each block's maximum into out[blockIdx.x]; the host combines the (at most kMaxReduceBlocks) values.
template <class Result, class Pass>
__global__ void __launch_bounds__(kBlock)
    reduce_kernel(const std::uint32_t* idx, std::size_t n, Result init, Pass pass, Result* out) {
  using BlockReduce = cub::BlockReduce<Result, kBlock>;
  __shared__ typename BlockReduce::TempStorage tmp;
  Result r = init;
  const std::size_t stride = std::size_t{gridDim.x} * blockDim.x;
  for (std::size_t k = std::size_t{blockIdx.x} * blockDim.x + threadIdx.x; k < n; k += stride)
    r = Result::max_of(r, pass(static_cast<std::size_t>(idx[k])));
  const Result b = BlockReduce(tmp).Reduce(r, MaxOf<Result>{});
  if (threadIdx.x == 0) out[blockIdx.x] = b;
}

// values[k] = pass(idx[k]) in double: the pass's side effects and values at full occupancy.
template <class Pass>
__global__ void __launch_bounds__(kBlock)
    value_kernel(const std::uint32_t* idx, std::size_t n, Pass pass, double* values) {
  const std::size_t stride = std::size_t{gridDim.x} * blockDim.x;
  for (std::size_t k = std::size_t{blockIdx.x} * blockDim.x + threadIdx.x; k < n; k += stride)
    values[k] = static_cast<double>(pass(static_cast<std::size_t>(idx[k])));
}

// partial[b] = the exact sum of values[b kSumBlock, (b + 1) kSumBlock) (core/exact_sum.hpp), one thread per
// block of kSumBlock, as the CPU's reduce_sum_n accumulates it: merged on the host, the sum has the CPU's
// bits. A template (Acc = ExactSum) so that the header can be included by several .cu files without
// defining the kernel twice.
template <class Acc>
__global__ void __launch_bounds__(kBlock)
    block_sum_kernel(const double* values, std::size_t n, Acc* partial, std::size_t blocks) {
  const std::size_t b = std::size_t{blockIdx.x} * blockDim.x + threadIdx.x;
  if (b >= blocks) return;
  const std::size_t begin = b * kSumBlock, end = begin + kSumBlock < n ? begin + kSumBlock : n;
  Acc s;
  s.add_terms(begin, end, [values](std::size_t k) { return values[k]; });
  s.normalize();
  partial[b] = s;
}

template <class Pred>
__global__ void __launch_bounds__(kBlock)
    first_kernel(const std::uint32_t* idx, std::size_t n, Pred pred, unsigned long long* first) {
  const std::size_t stride = std::size_t{gridDim.x} * blockDim.x;
  for (std::size_t k = std::size_t{blockIdx.x} * blockDim.x + threadIdx.x; k < n; k += stride) {
    const std::uint32_t i = idx[k];
    if (pred(static_cast<std::size_t>(i))) atomicMin(first, static_cast<unsigned long long>(i));
  }
}

}  // namespace cuda_detail

template <class Pass>
void run_pass(const DeviceIndexSet<CudaSpace>& set, const Pass& pass) {
  if (set.size == 0) return;
  cuda_detail::set_kernel<<<cuda_detail::blocks_for(set.size), cuda_detail::kBlock>>>(set.data, set.size,
                                                                                      pass);
  cuda_detail::check_launch("set_kernel<<<>>>");
}

template <class Pass>
void run_pass(const DeviceRange<CudaSpace>& range, const Pass& pass) {
  if (range.n == 0) return;
  cuda_detail::range_kernel<<<cuda_detail::blocks_for(range.n), cuda_detail::kBlock>>>(range.n, pass);
  cuda_detail::check_launch("range_kernel<<<>>>");
}

// Deterministic: a maximum, whatever the order of the blocks.
template <class Result, class Pass>
Result reduce_max(const DeviceIndexSet<CudaSpace>& set, Result init, const Pass& pass) {
  if (set.size == 0) return init;
  const unsigned blocks = cuda_detail::blocks_for(set.size, cuda_detail::kMaxReduceBlocks);
  DeviceArray<Result, CudaSpace> partial(blocks);
  cuda_detail::reduce_kernel<<<blocks, cuda_detail::kBlock>>>(set.data, set.size, init, pass, partial.data());
  cuda_detail::check_launch("reduce_kernel<<<>>>");
  std::vector<Result> host(blocks);
  partial.download(host.data());
  Result r = init;
  for (const Result& q : host) r = Result::max_of(r, q);
  return r;
}

// The CPU's sum, bit for bit: the values, the fixed blocks summed in order on the device, the block sums
// added in order on the host.
template <class Pass>
double reduce_sum(const DeviceIndexSet<CudaSpace>& set, const Pass& pass) {
  if (set.size == 0) return 0;
  DeviceArray<double, CudaSpace> values(set.size);
  cuda_detail::value_kernel<<<cuda_detail::blocks_for(set.size), cuda_detail::kBlock>>>(set.data, set.size,
                                                                                        pass, values.data());
  cuda_detail::check_launch("value_kernel<<<>>>");
  const std::size_t blocks = (set.size + kSumBlock - 1) / kSumBlock;
  DeviceArray<ExactSum, CudaSpace> partial(blocks);
  cuda_detail::block_sum_kernel<ExactSum><<<cuda_detail::blocks_for(blocks), cuda_detail::kBlock>>>(
      values.data(), set.size, partial.data(), blocks);
  cuda_detail::check_launch("block_sum_kernel<<<>>>");
  std::vector<ExactSum> host(blocks);
  partial.download(host.data());
  return merged_value(host);
}

// Deterministic: the minimum failing index.
template <class Pred>
std::int64_t first_where(const DeviceIndexSet<CudaSpace>& set, const Pred& pred) {
  if (set.size == 0) return -1;
  constexpr unsigned long long kNone = ~0ull;
  DeviceArray<unsigned long long, CudaSpace> first(1);
  first.upload(&kNone, 1);
  cuda_detail::first_kernel<<<cuda_detail::blocks_for(set.size), cuda_detail::kBlock>>>(set.data, set.size,
                                                                                        pred, first.data());
  cuda_detail::check_launch("first_kernel<<<>>>");
  const unsigned long long f = first.get(0);
  return f == kNone ? -1 : static_cast<std::int64_t>(f);
}

template <>
struct DeviceOps<CudaSpace> {
  using Bytes = DeviceArray<unsigned char, CudaSpace>;
  // CUB's LSD radix sort over bits [0, end_bit): stable, so indices stay ascending within a cell.
  static void sort_pairs(const std::uint32_t* keys_in, const std::uint32_t* vals_in, std::uint32_t* keys_out,
                         std::uint32_t* vals_out, std::size_t n, int end_bit, Bytes& scratch) {
    if (n == 0) return;
    std::size_t bytes = 0;
    const auto count = static_cast<std::int64_t>(n);
    CELLSPH_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, bytes, keys_in, keys_out, vals_in, vals_out,
                                                       count, 0, end_bit));
    scratch.resize(bytes);
    CELLSPH_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(scratch.data(), bytes, keys_in, keys_out, vals_in,
                                                       vals_out, count, 0, end_bit));
  }
  // Over n + 1 items (in[n] == 0), accumulated in T.
  template <class T>
  static void exclusive_scan(const std::uint32_t* in, T* out, std::size_t n, Bytes& scratch) {
    std::size_t bytes = 0;
    const auto count = static_cast<std::int64_t>(n + 1);
    CELLSPH_CUDA_CHECK(
        cub::DeviceScan::ExclusiveScan(nullptr, bytes, in, out, ::cuda::std::plus<>{}, T{0}, count));
    scratch.resize(bytes);
    CELLSPH_CUDA_CHECK(
        cub::DeviceScan::ExclusiveScan(scratch.data(), bytes, in, out, ::cuda::std::plus<>{}, T{0}, count));
  }
  static void synchronize() { CELLSPH_CUDA_CHECK(cudaDeviceSynchronize()); }
};

}  // namespace cellsph
