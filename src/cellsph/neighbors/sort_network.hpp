#pragma once
// Sorting short rows of distinct particle indices in AVX2 registers with a bitonic network: the row
// sort of Cell Indexing's find_all for rows of up to 64 (eight registers of eight lanes).
//
// The network is Batcher's bitonic sort written with every comparator ascending: for each block
// size k = 2, 4, ..., 8 NR, element e is first compared with e ^ (k - 1) (the two sorted halves of the
// block merged as if the upper one were reversed), then with e ^ j for j = k / 4, ..., 1. Distances of
// 8 and more pair two registers lane by lane (one min, one max); shorter ones pair lanes of one
// register (one shuffle, min, max and a blend). No branch depends on the data, unlike insertion sort,
// and the work is O(n log^2 n) in registers where the rank sort's is O(n^2 / 8).
#include <cstdint>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define CELLSPH_SORT_NETWORK_AVX2 1

namespace cellsph::detail {

// Lanes l and l ^ J of v compared; the lane with bit J set keeps the larger value. Flip = true
// pairs l with l ^ (2J - 1) instead (the first step of merging blocks of 2J lanes).
template <int J, bool Flip>
__attribute__((target("avx2"))) inline __m256i sort_lanes(__m256i v) {
  static_assert(J == 1 || J == 2 || J == 4);
  __m256i p;
  if constexpr (J == 1)
    p = _mm256_shuffle_epi32(v, 0xB1);  // l ^ 1 (the flip of blocks of two is the same pairing)
  else if constexpr (J == 2 && !Flip)
    p = _mm256_shuffle_epi32(v, 0x4E);  // l ^ 2
  else if constexpr (J == 2)
    p = _mm256_shuffle_epi32(v, 0x1B);  // l ^ 3
  else if constexpr (!Flip)
    p = _mm256_permute4x64_epi64(v, 0x4E);  // l ^ 4
  else
    p = _mm256_permutevar8x32_epi32(v, _mm256_setr_epi32(7, 6, 5, 4, 3, 2, 1, 0));  // l ^ 7
  constexpr int kUpper = J == 1 ? 0xAA : J == 2 ? 0xCC : 0xF0;
  return _mm256_blend_epi32(_mm256_min_epu32(v, p), _mm256_max_epu32(v, p), kUpper);
}

__attribute__((target("avx2"))) inline __m256i reverse_lanes(__m256i v) {
  return _mm256_permutevar8x32_epi32(v, _mm256_setr_epi32(7, 6, 5, 4, 3, 2, 1, 0));
}

// The in-register steps j = 4, 2, 1 of every block size of 8 and more.
template <int NR>
__attribute__((target("avx2"))) inline void sort_lanes_421(__m256i* r) {
#pragma GCC unroll 8
  for (int q = 0; q < NR; ++q) r[q] = sort_lanes<1, false>(sort_lanes<2, false>(sort_lanes<4, false>(r[q])));
}

// Half-cleaners across registers: register q with q + D (D, D / 2, ..., 1), the lower keeping minima.
template <int NR, int D>
__attribute__((target("avx2"))) inline void sort_registers_apart(__m256i* r) {
#pragma GCC unroll 8
  for (int q = 0; q < NR; ++q)
    if ((q & D) == 0) {
      const __m256i lo = r[q], hi = r[q + D];
      r[q] = _mm256_min_epu32(lo, hi);
      r[q + D] = _mm256_max_epu32(lo, hi);
    }
  if constexpr (D > 1) sort_registers_apart<NR, D / 2>(r);
}

// Merges sorted runs of Regs / 2 registers into runs of Regs (block size k = 8 Regs), then the next
// size up to NR. (Templates rather than loops: every register index is then a constant, and the
// registers stay in registers.)
template <int NR, int Regs>
__attribute__((target("avx2"))) inline void merge_registers(__m256i* r) {
  // Flip: register b + q of a block of Regs with register b + Regs - 1 - q, lanes reversed.
#pragma GCC unroll 8
  for (int b = 0; b < NR; b += Regs)
#pragma GCC unroll 8
    for (int q = 0; q < Regs / 2; ++q) {
      __m256i& lo = r[b + q];
      __m256i& hi = r[b + Regs - 1 - q];
      const __m256i t = reverse_lanes(hi);
      hi = reverse_lanes(_mm256_max_epu32(lo, t));
      lo = _mm256_min_epu32(lo, t);
    }
  if constexpr (Regs >= 4) sort_registers_apart<NR, Regs / 4>(r);
  sort_lanes_421<NR>(r);
  if constexpr (2 * Regs <= NR) merge_registers<NR, 2 * Regs>(r);
}

// Sorts the unsigned values of NR registers ascending across them (register 0 lane 0 the smallest).
template <int NR>
__attribute__((target("avx2"))) inline void bitonic_sort_registers(__m256i* r) {
  static_assert(NR == 1 || NR == 2 || NR == 4 || NR == 8);
#pragma GCC unroll 8
  for (int q = 0; q < NR; ++q) {
    r[q] = sort_lanes<1, true>(r[q]);                                              // k = 2
    r[q] = sort_lanes<1, false>(sort_lanes<2, true>(r[q]));                        // k = 4
    r[q] = sort_lanes<1, false>(sort_lanes<2, false>(sort_lanes<4, true>(r[q])));  // k = 8
  }
  if constexpr (NR >= 2) merge_registers<NR, 2>(r);
}

// Sorts the distinct values in[0, L) into out[0, L), 8 (NR - 1) < L <= 8 NR. Reads in[0, 8 NR) (the
// entries from L on are ignored: read as padding that sorts last); writes out[0, L) only.
template <int NR>
__attribute__((target("avx2"))) inline void sort_network_avx2(const std::uint32_t* in, std::uint32_t L,
                                                              std::uint32_t* out) {
  __m256i r[NR];
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i last = _mm256_set1_epi32(static_cast<int>(L) - 1);
#pragma GCC unroll 8
  for (int q = 0; q < NR; ++q) {
    // Lanes at or past L become UINT32_MAX, which no particle index is.
    const __m256i past = _mm256_cmpgt_epi32(_mm256_add_epi32(lane, _mm256_set1_epi32(8 * q)), last);
    r[q] = _mm256_or_si256(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(in + 8 * q)), past);
  }
  bitonic_sort_registers<NR>(r);
#pragma GCC unroll 8
  for (int q = 0; q < NR; ++q) {
    const int left = static_cast<int>(L) - 8 * q;
    if (left >= 8)
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + 8 * q), r[q]);
    else if (left > 0)  // the last, partial register
      _mm256_maskstore_epi32(reinterpret_cast<int*>(out + 8 * q),
                             _mm256_cmpgt_epi32(_mm256_set1_epi32(left), lane), r[q]);
  }
}

// Sorts the distinct values in[0, L), 1 <= L <= 64, into out[0, L) with the smallest network that
// holds them: reads in[0, 8), [0, 16), [0, 32) or [0, 64).
__attribute__((target("avx2"))) inline void sort_row_avx2(const std::uint32_t* in, std::uint32_t L,
                                                          std::uint32_t* out) {
  if (L <= 8)
    sort_network_avx2<1>(in, L, out);
  else if (L <= 16)
    sort_network_avx2<2>(in, L, out);
  else if (L <= 32)
    sort_network_avx2<4>(in, L, out);
  else
    sort_network_avx2<8>(in, L, out);
}

}  // namespace cellsph::detail
#endif
