#pragma once
// Cell Indexing's inner loops at three widths: the distance test of a block of candidates (hits64_*),
// the left-packing of a hit mask (AVX2 only) and the rank sort of a short row (rank_sort_*). Every
// width does the same float operations in the same order (no FMA), so every result is identical
// whichever runs; the build targets baseline x86-64 and the AVX2 code is chosen at run time.
//
// Which path runs (simd_path()) is the best the CPU has, or a lower one named by the environment
// variable CELLSPH_SIMD (scalar, sse2 or avx2): the tests run the searches once more on each lower
// path that way, and a user can rule out a SIMD fault in the field.
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <string>

#include "cellsph/core/error.hpp"
#include "cellsph/neighbors/sort_network.hpp"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define CELLSPH_CELL_INDEX_X86 1
#endif

namespace cellsph {

enum class SimdPath : std::uint8_t { Scalar, Sse2, Avx2 };

inline const char* simd_path_name(SimdPath p) {
  switch (p) {
    case SimdPath::Scalar:
      return "scalar";
    case SimdPath::Sse2:
      return "sse2";
    case SimdPath::Avx2:
      return "avx2";
  }
  return "?";
}

// The widest path this build and CPU can run.
inline SimdPath best_simd_path() {
#if defined(CELLSPH_CELL_INDEX_X86)
  return __builtin_cpu_supports("avx2") ? SimdPath::Avx2 : SimdPath::Sse2;
#else
  return SimdPath::Scalar;
#endif
}

// The path that CELLSPH_SIMD's value names (null or empty: best); a name that is not a path, or a path
// wider than best, is an input error naming the variable and its value.
inline SimdPath parse_simd_path(const char* value, SimdPath best) {
  if (value == nullptr || *value == '\0') return best;
  const std::string v(value);
  for (SimdPath p : {SimdPath::Scalar, SimdPath::Sse2, SimdPath::Avx2})
    if (v == simd_path_name(p)) {
      if (p > best)
        throw InputError("CELLSPH_SIMD=" + v + ": this " +
                         (best == SimdPath::Scalar ? std::string("build") : std::string("CPU")) +
                         " runs at most " + simd_path_name(best));
      return p;
    }
  throw InputError("CELLSPH_SIMD=" + v + ": expected scalar, sse2 or avx2 (or unset: the best, " +
                   simd_path_name(best) + ")");
}

// The path every search of this process runs, fixed at its first call.
inline SimdPath simd_path() {
  static const SimdPath path = parse_simd_path(std::getenv("CELLSPH_SIMD"), best_simd_path());
  return path;
}

namespace detail {

// Bits t < m <= 64 with d2 <= hi2, d2 the float distance2 of xi and candidate t of ax (the operations
// of distance2, in its order); with Band, *sure gets those with d2 <= lo2 (CellIndex::hits64 says why
// two bounds).
template <int Dim, bool Band>
std::uint64_t hits64_scalar(const float* const* ax, const float* xi, float lo2, float hi2, std::uint32_t m,
                            std::uint64_t* sure) {
  std::uint64_t bits = 0, in = 0;
  for (std::uint32_t t = 0; t < m; ++t) {
    float d = xi[0] - ax[0][t];
    float s2 = d * d;
    for (int k = 1; k < Dim; ++k) {
      d = xi[k] - ax[k][t];
      s2 += d * d;
    }
    bits |= static_cast<std::uint64_t>(s2 <= hi2) << t;
    if constexpr (Band) in |= static_cast<std::uint64_t>(s2 <= lo2) << t;
  }
  const std::uint64_t all = m == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << m) - 1;
  if constexpr (Band) *sure = in & all;
  return bits & all;
}

// Sorts the distinct in[0, L) into out by rank: out[#{m : in[m] < in[k]}] = in[k].
inline void rank_sort_scalar(const std::uint32_t* in, std::uint32_t L, std::uint32_t* out) {
  for (std::uint32_t k = 0; k < L; ++k) {
    std::uint32_t rank = 0;
    for (std::uint32_t m = 0; m < L; ++m) rank += in[m] < in[k] ? 1u : 0u;
    out[rank] = in[k];
  }
}

#if defined(CELLSPH_CELL_INDEX_X86)
// hits64_scalar four candidates at a time. Reads up to 3 entries past ax[k][m - 1] (padding).
template <int Dim, bool Band>
std::uint64_t hits64_sse2(const float* const* ax, const float* xi, float lo2, float hi2, std::uint32_t m,
                          std::uint64_t* sure) {
  std::uint64_t bits = 0, in = 0;
  const __m128 h2 = _mm_set1_ps(hi2), l2 = _mm_set1_ps(lo2);
  for (std::uint32_t t = 0; t < m; t += 4) {
    __m128 d = _mm_sub_ps(_mm_set1_ps(xi[0]), _mm_loadu_ps(ax[0] + t));
    __m128 s2 = _mm_mul_ps(d, d);
    for (int k = 1; k < Dim; ++k) {
      d = _mm_sub_ps(_mm_set1_ps(xi[k]), _mm_loadu_ps(ax[k] + t));
      s2 = _mm_add_ps(s2, _mm_mul_ps(d, d));
    }
    bits |= static_cast<std::uint64_t>(_mm_movemask_ps(_mm_cmple_ps(s2, h2))) << t;
    if constexpr (Band) in |= static_cast<std::uint64_t>(_mm_movemask_ps(_mm_cmple_ps(s2, l2))) << t;
  }
  const std::uint64_t all = m == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << m) - 1;
  if constexpr (Band) *sure = in & all;
  return bits & all;
}

// rank_sort_scalar with the inner count four at a time. in needs 3 readable entries past L whose
// values are the largest (UINT32_MAX), so that they count for no rank.
inline void rank_sort_sse2(const std::uint32_t* in, std::uint32_t L, std::uint32_t* out) {
  const __m128i bias = _mm_set1_epi32(static_cast<int>(0x80000000u));  // unsigned order via signed compare
  for (std::uint32_t k = 0; k < L; ++k) {
    const __m128i v = _mm_xor_si128(_mm_set1_epi32(static_cast<int>(in[k])), bias);
    __m128i acc = _mm_setzero_si128();
    for (std::uint32_t m = 0; m < L; m += 4) {
      const __m128i w = _mm_xor_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(in + m)), bias);
      acc = _mm_sub_epi32(acc, _mm_cmplt_epi32(w, v));
    }
    acc = _mm_add_epi32(acc, _mm_shuffle_epi32(acc, 0x4E));
    acc = _mm_add_epi32(acc, _mm_shuffle_epi32(acc, 0xB1));
    out[_mm_cvtsi128_si32(acc)] = in[k];
  }
}

// Bits t < m <= 64 with d2 <= hi2, d2 the float distance2 of xi and candidate t of ax; with Band,
// *sure gets those with d2 <= lo2 (CellIndex::hits64 says why two bounds).
template <int Dim, bool Band>
__attribute__((target("avx2"))) std::uint64_t hits64_avx2(const float* const* ax, const float* xi, float lo2,
                                                          float hi2, std::uint32_t m, std::uint64_t* sure) {
  std::uint64_t bits = 0, in = 0;
  const __m256 h2 = _mm256_set1_ps(hi2), l2 = _mm256_set1_ps(lo2);
  for (std::uint32_t t = 0; t < m; t += 8) {
    __m256 d = _mm256_sub_ps(_mm256_set1_ps(xi[0]), _mm256_loadu_ps(ax[0] + t));
    __m256 s2 = _mm256_mul_ps(d, d);
    for (int k = 1; k < Dim; ++k) {
      d = _mm256_sub_ps(_mm256_set1_ps(xi[k]), _mm256_loadu_ps(ax[k] + t));
      s2 = _mm256_add_ps(s2, _mm256_mul_ps(d, d));
    }
    bits |= static_cast<std::uint64_t>(_mm256_movemask_ps(_mm256_cmp_ps(s2, h2, _CMP_LE_OQ))) << t;
    if constexpr (Band)
      in |= static_cast<std::uint64_t>(_mm256_movemask_ps(_mm256_cmp_ps(s2, l2, _CMP_LE_OQ))) << t;
  }
  const std::uint64_t all = m == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << m) - 1;
  if constexpr (Band) *sure = in & all;
  return bits & all;
}

// Permutations that move the lanes set in an 8-bit mask to the front, in order (left-packing).
struct LeftPackTable {
  alignas(32) std::uint32_t lane[256][8];
  std::uint8_t count[256];
  constexpr LeftPackTable() : lane{}, count{} {
    for (int m = 0; m < 256; ++m) {
      int c = 0;
      for (int t = 0; t < 8; ++t)
        if ((m >> t) & 1) lane[m][c++] = static_cast<std::uint32_t>(t);
      count[m] = static_cast<std::uint8_t>(c);
    }
  }
};
inline constexpr LeftPackTable kLeftPack{};

// Writes id[t] for every bit t set in bits (t < m <= 64) to dst, in order; returns how many. Writes
// up to 8 entries past the last one and reads up to 8 past id[m - 1] (both must be padding).
__attribute__((target("avx2"))) inline std::uint32_t left_pack_avx2(const std::uint32_t* id,
                                                                    std::uint64_t bits, std::uint32_t m,
                                                                    std::uint32_t* dst) {
  std::uint32_t c = 0;
  for (std::uint32_t t = 0; t < m && (bits >> t) != 0; t += 8) {
    const auto k = static_cast<unsigned>((bits >> t) & 0xFFu);
    const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(id + t));
    const __m256i perm = _mm256_load_si256(reinterpret_cast<const __m256i*>(kLeftPack.lane[k]));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(dst + c), _mm256_permutevar8x32_epi32(v, perm));
    c += kLeftPack.count[k];
  }
  return c;
}

// Ranks of the NB * 8 values biased[k0, k0 + 8 NB) among biased[0, L): each biased[m] is broadcast
// once and compared with all NB registers, whose NB sums are independent (no one chain of L adds).
template <int NB>
__attribute__((target("avx2"))) inline void rank_block_avx2(const std::int32_t* biased, std::uint32_t L,
                                                            std::uint32_t k0, std::uint32_t* rank) {
  __m256i v[NB], acc[NB];
  for (int b = 0; b < NB; ++b) {
    v[b] = _mm256_load_si256(reinterpret_cast<const __m256i*>(biased + k0 + 8 * b));
    acc[b] = _mm256_setzero_si256();
  }
  for (std::uint32_t m = 0; m < L; ++m) {
    const __m256i w = _mm256_set1_epi32(biased[m]);
    for (int b = 0; b < NB; ++b) acc[b] = _mm256_sub_epi32(acc[b], _mm256_cmpgt_epi32(v[b], w));
  }
  for (int b = 0; b < NB; ++b) _mm256_store_si256(reinterpret_cast<__m256i*>(rank + 8 * b), acc[b]);
}

// Sorts the distinct in[0, L) (L <= kMax) into out by rank, out[#{m : in[m] < in[k]}] = in[k], eight
// values of k to a register and up to four registers at a time: each in[m] is broadcast once and
// compared with all of them, so the ranks come out in registers, with no horizontal sum. Reads up to
// 8 entries past in[L - 1].
template <std::uint32_t kMax>
__attribute__((target("avx2"))) inline void rank_sort_avx2(const std::uint32_t* in, std::uint32_t L,
                                                           std::uint32_t* out) {
  // Unsigned order through the signed compare: flip the top bit of every value once. Entries past L
  // (up to the next 32) are read as a block's padding; their ranks are never used.
  alignas(32) std::int32_t biased[kMax + 32];
  const __m256i bias = _mm256_set1_epi32(static_cast<int>(0x80000000u));
  std::uint32_t m = 0;
  for (; m < L; m += 8)
    _mm256_store_si256(reinterpret_cast<__m256i*>(biased + m),
                       _mm256_xor_si256(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(in + m)), bias));
  for (; m < ((L + 31) & ~31u); m += 8) _mm256_store_si256(reinterpret_cast<__m256i*>(biased + m), bias);
  alignas(32) std::uint32_t rank[32];
  for (std::uint32_t k0 = 0; k0 < L; k0 += 32) {
    const std::uint32_t left = L - k0;
    if (left > 24)
      rank_block_avx2<4>(biased, L, k0, rank);
    else if (left > 16)
      rank_block_avx2<3>(biased, L, k0, rank);
    else if (left > 8)
      rank_block_avx2<2>(biased, L, k0, rank);
    else
      rank_block_avx2<1>(biased, L, k0, rank);
    const std::uint32_t e = std::min<std::uint32_t>(32, left);
    for (std::uint32_t t = 0; t < e; ++t) out[rank[t]] = in[k0 + t];
  }
}
#endif  // CELLSPH_CELL_INDEX_X86

}  // namespace detail
}  // namespace cellsph
