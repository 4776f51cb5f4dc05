#pragma once
// The exact sum of doubles, rounded once at the end: a long fixed-point accumulator (Kulisch's idea) whose
// value does not depend on the order of the additions or on how the terms were split between threads,
// blocks, kernels or ranks. It is what makes every global sum of a run (DFSPH's and IISPH's average
// errors, the conjugate-gradient products, the counts) give the same bits for any thread count, on the CPU
// or a GPU, and on any number of MPI ranks (issue 49): the per-part accumulators are merged exactly, and
// the merge of integers is associative.
//
// Layout: digit k (int64) weighs 2^(32 k - 1074), so bit 0 is the smallest subnormal and 67 digits cover
// the largest double times 2^31 terms. A term is split into at most three 32-bit pieces added to three
// digits; each digit holds 2^29 such additions before a carry pass (`normalize`) brings every digit but
// the top one back to [0, 2^32). Infinities and NaN are kept apart as flags, as IEEE addition would treat
// them (+inf and -inf together give NaN). `value()` rounds to nearest, ties to even. Written for the host
// and the device (CELLSPH_HD), without a branch on a term's sign. Cost: about 3 ns a term against 1 ns for
// a plain double sum (`add_terms`, 2^20 random terms, the 2-core VM of docs/benchmarks.md).
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "cellsph/core/hd.hpp"

namespace cellsph {

class ExactSum {
 public:
  static constexpr int kDigits = 67;

  // A term cut into the pieces added to three digits (k, k + 1, k + 2), or a special value or zero.
  struct Piece {
    int k = 0;
    std::int64_t c0 = 0, c1 = 0, c2 = 0;  // signed: negative for a negative term
    std::uint32_t special = 0;            // kPlusInf, kMinusInf or kNan
    bool zero = true;
  };

  CELLSPH_HD static Piece cut(double x) {
    Piece q;
    const std::uint64_t b = bits_of(x);
    const auto exponent = static_cast<int>((b >> 52) & 0x7FF);
    std::uint64_t m = b & ((std::uint64_t{1} << 52) - 1);
    const bool negative = (b >> 63) != 0;
    if (exponent == 0x7FF) {
      q.special = m != 0 ? kNan : negative ? kMinusInf : kPlusInf;
      return q;
    }
    int p = 0;  // the position of m's lowest bit: x = m 2^(p - 1074)
    if (exponent != 0) {
      m |= std::uint64_t{1} << 52;
      p = exponent - 1;
    }
    if (m == 0) return q;
    q.zero = false;
    q.k = p >> 5;
    const int s = p & 31;
    const std::uint64_t low = (m & kMask) << s, high = (m >> 32) << s;  // m 2^s = low + high 2^32
    q.c0 = static_cast<std::int64_t>(low & kMask);
    q.c1 = static_cast<std::int64_t>((low >> 32) + (high & kMask));
    q.c2 = static_cast<std::int64_t>(high >> 32);
    // Negated without a branch (a term's sign is as good as random: a branch mispredicts every other term).
    const std::int64_t minus = -static_cast<std::int64_t>(negative);  // all ones or zero
    q.c0 = (q.c0 ^ minus) - minus;
    q.c1 = (q.c1 ^ minus) - minus;
    q.c2 = (q.c2 ^ minus) - minus;
    return q;
  }

  CELLSPH_HD void add(double x) {
    const Piece q = cut(x);
    if (q.special != 0) special_ |= q.special;
    if (q.zero) return;
    d_[q.k] += q.c0;
    d_[q.k + 1] += q.c1;
    d_[q.k + 2] += q.c2;
    if (++pending_ >= kPendingLimit) normalize();
  }

  // Adds term(i) for i in [begin, end): the same value as add() for each, without add()'s count of
  // pending additions a term (the terms are counted a chunk of at most 2^20 at a time: below 2^53 a digit).
  // The chunk's digits are a local array: the compiler then knows that its writes change nothing `term`
  // reads (writes to this object's digits, 64-bit integers, could alias what `term` reads).
  template <class Term>
  CELLSPH_HD void add_terms(std::size_t begin, std::size_t end, const Term& term) {
    while (begin < end) {
      const std::size_t stop = end - begin > kChunk ? begin + kChunk : end;
      std::uint32_t special = 0;
      std::int64_t local[kDigits] = {};
      for (std::size_t i = begin; i < stop; ++i) {
        const Piece q = cut(static_cast<double>(term(i)));
        special |= q.special;
        local[q.k] += q.c0;  // a zero or special term's pieces are 0 (at digit 0)
        local[q.k + 1] += q.c1;
        local[q.k + 2] += q.c2;
      }
      for (int k = 0; k < kDigits; ++k) d_[k] += local[k];
      special_ |= special;
      // Each digit took at most 2^20 pieces below 2^33: a carry pass every 2^9 chunks keeps it below 2^63.
      pending_ = pending_ < kPendingLimit - kChunkWeight ? pending_ + kChunkWeight : kPendingLimit;
      if (pending_ >= kPendingLimit) normalize();
      begin = stop;
    }
  }

  // Adds another accumulator's exact value (and its infinities and NaN).
  CELLSPH_HD void merge(const ExactSum& other) {
    ExactSum o = other;
    o.normalize();
    normalize();
    for (int k = 0; k < kDigits; ++k) d_[k] += o.d_[k];
    special_ |= o.special_;
    normalize();
  }

  // Carries: every digit but the top one into [0, 2^32), the top one signed. The representation of a
  // value is then unique, so two accumulators of the same value hold the same digits.
  CELLSPH_HD void normalize() {
    for (int k = 0; k + 1 < kDigits; ++k) {
      const std::int64_t carry = d_[k] >> 32;  // arithmetic shift: floor(d / 2^32)
      d_[k] -= carry * (std::int64_t{1} << 32);
      d_[k + 1] += carry;
    }
    pending_ = 0;
  }

  // The exact sum rounded to the nearest double (ties to even); +0 for an exact zero.
  CELLSPH_HD double value() const {
    if (special_ & kNan || (special_ & kPlusInf && special_ & kMinusInf)) return nan_value();
    if (special_ & kPlusInf) return inf_value();
    if (special_ & kMinusInf) return -inf_value();
    ExactSum a = *this;
    a.normalize();
    const bool negative = a.d_[kDigits - 1] < 0;
    if (negative) {
      for (int k = 0; k < kDigits; ++k) a.d_[k] = -a.d_[k];
      a.normalize();
    }
    int h = kDigits - 1;
    while (h >= 0 && a.d_[h] == 0) --h;
    if (h < 0) return 0.0;
    const auto digit = [&](int k) { return k >= 0 ? static_cast<std::uint64_t>(a.d_[k]) : std::uint64_t{0}; };
    double r = 0;
    const std::uint64_t small = h <= 1 ? (digit(1) << 32) | digit(0) : 0;
    if (h <= 1 && small < (std::uint64_t{1} << 53)) {
      r = scale(static_cast<double>(small), -1074);  // an exact multiple of the smallest subnormal
    } else {
      // The top 64 bits (the leading one at bit 63), the rest as a sticky bit.
      const int lz = leading_zeros32(static_cast<std::uint32_t>(digit(h)));
      const std::uint64_t top96_hi = (digit(h) << 32) | digit(h - 1);
      std::uint64_t top = lz == 0 ? top96_hi : (top96_hi << lz) | (digit(h - 2) >> (32 - lz));
      bool sticky = (digit(h - 2) & ((std::uint64_t{1} << (32 - lz)) - 1)) != 0;
      for (int k = h - 3; k >= 0 && !sticky; --k) sticky = a.d_[k] != 0;
      std::uint64_t mantissa = top >> 11;
      const std::uint64_t rest = top & 0x7FF;
      const bool half = (rest >> 10) != 0;
      sticky = sticky || (rest & 0x3FF) != 0;
      if (half && (sticky || (mantissa & 1))) ++mantissa;
      // The leading bit weighs 2^(32 h + 31 - lz - 1074); the mantissa's lowest 2^(that - 52).
      r = scale(static_cast<double>(mantissa), 32 * h + 31 - lz - 1074 - 52);
    }
    return negative ? -r : r;
  }

  // The digits, for an exchange between ranks (normalized first: each in [0, 2^32) but the top one).
  CELLSPH_HD const std::int64_t* digits() const { return d_; }
  CELLSPH_HD std::int64_t* digits() { return d_; }
  CELLSPH_HD std::uint32_t special() const { return special_; }
  CELLSPH_HD void set_special(std::uint32_t s) { special_ = s; }

 private:
  static constexpr std::uint64_t kMask = 0xFFFFFFFFull;
  static constexpr std::uint32_t kPendingLimit = 1u << 29;
  static constexpr std::uint32_t kPlusInf = 1, kMinusInf = 2, kNan = 4;

  static constexpr std::size_t kChunk = std::size_t{1} << 20;
  // A chunk counts as 2^20 additions toward the carry pass (add() counts one a term).
  static constexpr std::uint32_t kChunkWeight = 1u << 20;

  CELLSPH_HD static std::uint64_t bits_of(double x) {
#if defined(__CUDA_ARCH__)
    return static_cast<std::uint64_t>(__double_as_longlong(x));
#else
    std::uint64_t b;
    std::memcpy(&b, &x, sizeof b);
    return b;
#endif
  }
  CELLSPH_HD static int leading_zeros32(std::uint32_t v) {
#if defined(__CUDA_ARCH__)
    return __clz(static_cast<int>(v));
#else
    return __builtin_clz(v);
#endif
  }
  // x 2^e for an integer-valued x <= 2^53: exact in the normal range (and for the subnormal multiples of
  // 2^-1074 that value() passes), infinity beyond it.
  CELLSPH_HD static double scale(double x, int e) {
#if defined(__CUDA_ARCH__)
    return ::ldexp(x, e);
#else
    return std::ldexp(x, e);
#endif
  }
  CELLSPH_HD static double inf_value() {
    return std::numeric_limits<double>::infinity();
  }
  CELLSPH_HD static double nan_value() {
    return std::numeric_limits<double>::quiet_NaN();
  }

  std::int64_t d_[kDigits] = {};
  std::uint32_t pending_ = 0;
  std::uint32_t special_ = 0;
};

}  // namespace cellsph
