#include "cellsph/neighbors/radix_sort.hpp"

#include <algorithm>
#include <bit>
#include <utility>

#include <omp.h>

#include "cellsph/core/error.hpp"

namespace cellsph {
namespace {

// Below this size a single thread does the work: forking costs more than it saves.
constexpr std::size_t kSerialBelow = 1 << 14;

struct PassPlan {
  int lo = 0;      // first varying bit
  int hi = 0;      // one past the last varying bit
  int passes = 0;  // number of digit passes
  int width = 0;   // bits per digit
};

std::uint64_t range_mask(int begin_bit, int end_bit) {
  const std::uint64_t hi = end_bit >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << end_bit) - 1;
  const std::uint64_t lo = begin_bit >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << begin_bit) - 1;
  return hi & ~lo;
}

PassPlan plan_passes(const std::uint64_t* k, std::size_t n, int begin_bit, int end_bit) {
  CELLSPH_CHECK(0 <= begin_bit && begin_bit <= end_bit && end_bit <= 64,
                "bad radix bit range [" << begin_bit << ", " << end_bit << ")");
  std::uint64_t all_or = 0, all_and = ~std::uint64_t{0};
  const auto count = static_cast<std::int64_t>(n);
#pragma omp parallel for reduction(| : all_or) reduction(& : all_and) if (n >= kSerialBelow)
  for (std::int64_t i = 0; i < count; ++i) {
    all_or |= k[i];
    all_and &= k[i];
  }
  const std::uint64_t varying = (all_or ^ all_and) & range_mask(begin_bit, end_bit);
  PassPlan p;
  if (n < 2 || varying == 0) return p;
  p.lo = std::countr_zero(varying);
  p.hi = 64 - std::countl_zero(varying);
  const int span = p.hi - p.lo;
  p.passes = (span + kRadixMaxDigitBits - 1) / kRadixMaxDigitBits;
  p.width = (span + p.passes - 1) / p.passes;
  return p;
}

// One stable counting pass on digit (key >> shift) & mask, from (k, v) into (kd, vd).
template <bool WithPayload>
void radix_pass(const std::uint64_t* k, const std::uint32_t* v, std::uint64_t* kd, std::uint32_t* vd,
                std::size_t n, int shift, int width, std::vector<std::size_t>& hist) {
  const std::size_t buckets = std::size_t{1} << width;
  const std::uint64_t mask = buckets - 1;
  const int max_t = omp_get_max_threads();
  hist.assign(static_cast<std::size_t>(max_t) * buckets, 0);
#pragma omp parallel if (n >= kSerialBelow)
  {
    const auto nt = static_cast<std::size_t>(omp_get_num_threads());
    const auto t = static_cast<std::size_t>(omp_get_thread_num());
    const std::size_t b = n * t / nt, e = n * (t + 1) / nt;
    std::size_t* h = hist.data() + t * buckets;
    for (std::size_t i = b; i < e; ++i) ++h[(k[i] >> shift) & mask];
#pragma omp barrier
#pragma omp single
    {
      // Bucket-major, thread-minor exclusive prefix sum: keeps the pass stable.
      std::size_t run = 0;
      for (std::size_t d = 0; d < buckets; ++d)
        for (std::size_t s = 0; s < nt; ++s) {
          std::size_t& c = hist[s * buckets + d];
          const std::size_t c0 = c;
          c = run;
          run += c0;
        }
    }
    for (std::size_t i = b; i < e; ++i) {
      const std::size_t pos = h[(k[i] >> shift) & mask]++;
      kd[pos] = k[i];
      if constexpr (WithPayload) vd[pos] = v[i];
    }
  }
}

template <bool WithPayload>
void sort_impl(std::vector<std::uint64_t>& keys, std::vector<std::uint32_t>* payload,
               std::vector<std::uint64_t>& key_scratch, std::vector<std::uint32_t>* payload_scratch,
               int begin_bit, int end_bit) {
  const std::size_t n = keys.size();
  const PassPlan plan = plan_passes(keys.data(), n, begin_bit, end_bit);
  if (plan.passes == 0) return;
  key_scratch.resize(n);
  if constexpr (WithPayload) payload_scratch->resize(n);
  std::vector<std::size_t> hist;
  for (int p = 0; p < plan.passes; ++p) {
    const int shift = plan.lo + p * plan.width;
    // The last digit stops at the last varying bit: bits outside [begin_bit, end_bit) must not
    // take part in the order.
    const int width = std::min(plan.width, plan.hi - shift);
    if constexpr (WithPayload) {
      radix_pass<true>(keys.data(), payload->data(), key_scratch.data(), payload_scratch->data(), n, shift,
                       width, hist);
      payload->swap(*payload_scratch);
    } else {
      radix_pass<false>(keys.data(), nullptr, key_scratch.data(), nullptr, n, shift, width, hist);
    }
    keys.swap(key_scratch);
  }
}

}  // namespace

void radix_sort(std::vector<std::uint64_t>& keys, std::vector<std::uint64_t>& scratch, int begin_bit,
                int end_bit) {
  sort_impl<false>(keys, nullptr, scratch, nullptr, begin_bit, end_bit);
}

std::uint64_t* radix_sort(std::span<std::uint64_t> keys, std::span<std::uint64_t> scratch, int begin_bit,
                          int end_bit) {
  const std::size_t n = keys.size();
  CELLSPH_CHECK(scratch.size() >= n, "radix_sort: scratch of " << scratch.size() << " for " << n << " keys");
  const PassPlan plan = plan_passes(keys.data(), n, begin_bit, end_bit);
  std::uint64_t* from = keys.data();
  std::uint64_t* to = scratch.data();
  std::vector<std::size_t> hist;
  for (int p = 0; p < plan.passes; ++p) {
    const int shift = plan.lo + p * plan.width;
    const int width = std::min(plan.width, plan.hi - shift);
    radix_pass<false>(from, nullptr, to, nullptr, n, shift, width, hist);
    std::swap(from, to);
  }
  return from;
}

void radix_sort_pairs(std::vector<std::uint64_t>& keys, std::vector<std::uint32_t>& payload,
                      std::vector<std::uint64_t>& key_scratch, std::vector<std::uint32_t>& payload_scratch,
                      int begin_bit, int end_bit) {
  CELLSPH_CHECK(keys.size() == payload.size(),
                "radix_sort_pairs: " << keys.size() << " keys but " << payload.size() << " payloads");
  sort_impl<true>(keys, &payload, key_scratch, &payload_scratch, begin_bit, end_bit);
}

int radix_sort_passes(const std::vector<std::uint64_t>& keys, int begin_bit, int end_bit) {
  return plan_passes(keys.data(), keys.size(), begin_bit, end_bit).passes;
}

}  // namespace cellsph
