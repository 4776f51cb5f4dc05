#pragma once
// The pass driver of the device backends (pass_driver.hpp is the CPU's). A device index set names
// indices held in the space's memory; run_pass, reduce_max, reduce_sum and first_where are overloaded for it,
// so the
// model files' functions (templated on the set type) run their passes on a device unchanged. Besides the
// passes, a device step needs three primitives, in DeviceOps<Space>: a stable sort of (key, index) pairs
// on the low key bits, an exclusive scan of counts, and a synchronisation point.
//
// Here: the host-emulated device (HostDeviceSpace), with the CPU driver's loops over the index arrays.
// The CUDA versions (kernel launches, CUB) are in cuda/cuda_driver.cuh, seen only by nvcc.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <vector>

#include "cellsph/core/parallel.hpp"
#include "cellsph/solver/device/memory_space.hpp"
#include "cellsph/solver/pass_driver.hpp"

namespace cellsph {

// Indices data[0 .. size) in Space's memory.
template <class Space>
struct DeviceIndexSet {
  const std::uint32_t* data = nullptr;
  std::size_t size = 0;
};

template <class Space>
std::size_t set_size(const DeviceIndexSet<Space>& set) {
  return set.size;
}

// Every index in [0, n).
template <class Space>
struct DeviceRange {
  std::size_t n = 0;
};

template <class Space>
struct DeviceOps;

// ---- HostDeviceSpace

template <class Pass>
void run_pass(const DeviceIndexSet<HostDeviceSpace>& set, const Pass& pass) {
  const std::uint32_t* idx = set.data;
  parallel_for(set.size, [&](std::size_t k) { pass(static_cast<std::size_t>(idx[k])); });
}

template <class Pass>
void run_pass(const DeviceRange<HostDeviceSpace>& range, const Pass& pass) {
  parallel_for(range.n, [&](std::size_t i) { pass(i); });
}

template <class Result, class Pass>
Result reduce_max(const DeviceIndexSet<HostDeviceSpace>& set, Result init, const Pass& pass) {
  return reduce_max_n(set.data, set.size, init, pass);
}

template <class Pass>
double reduce_sum(const DeviceIndexSet<HostDeviceSpace>& set, const Pass& pass) {
  return reduce_sum_n(set.data, set.size, pass);
}

template <class Pred>
std::int64_t first_where(const DeviceIndexSet<HostDeviceSpace>& set, const Pred& pred) {
  return first_where_n(set.data, set.size, pred);
}

template <>
struct DeviceOps<HostDeviceSpace> {
  using Bytes = DeviceArray<unsigned char, HostDeviceSpace>;
  // (keys_out, vals_out) = (keys_in, vals_in) sorted by key, stable; only bits [0, end_bit) of the keys
  // are set. The CUDA version is CUB's radix sort over those bits.
  static void sort_pairs(const std::uint32_t* keys_in, const std::uint32_t* vals_in, std::uint32_t* keys_out,
                         std::uint32_t* vals_out, std::size_t n, int /*end_bit*/, Bytes& /*scratch*/) {
    std::vector<std::uint32_t> order(n);
    std::iota(order.begin(), order.end(), std::uint32_t{0});
    std::stable_sort(order.begin(), order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return keys_in[a] < keys_in[b]; });
    for (std::size_t k = 0; k < n; ++k) {
      keys_out[k] = keys_in[order[k]];
      vals_out[k] = vals_in[order[k]];
    }
  }
  // out[0] = 0, out[k + 1] = in[0] + ... + in[k] for k < n, summed in T. `in` has n + 1 entries, the last
  // 0 (so a device scan runs over n + 1 items).
  template <class T>
  static void exclusive_scan(const std::uint32_t* in, T* out, std::size_t n, Bytes& /*scratch*/) {
    T s = 0;
    out[0] = 0;
    for (std::size_t k = 0; k < n; ++k) out[k + 1] = s += in[k];
  }
  static void synchronize() {}
};

}  // namespace cellsph
