#include "cellsph/core/exact_sum.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace cellsph {
namespace {

__extension__ typedef __int128 Int128;  // GCC's and Clang's 128-bit integer (the reference's exact sum)

std::uint64_t bits(double x) {
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

double exact_sum_of(const std::vector<double>& xs) {
  ExactSum s;
  for (const double x : xs) s.add(x);
  return s.value();
}

TEST(ExactSum, CancellationThatPlainAdditionLoses) {
  EXPECT_EQ(exact_sum_of({1e300, 1.0, -1e300}), 1.0);      // in order, double addition gives 0
  EXPECT_EQ(exact_sum_of({1e308, 1e308, -1e308}), 1e308);  // double addition overflows to inf
  EXPECT_EQ(exact_sum_of({1.0, 1e-300, -1.0}), 1e-300);    // double addition gives 0
  // 0.1 + 0.2 - 0.3 of the three doubles' exact binary values (worked out with Python's fractions).
  EXPECT_EQ(exact_sum_of({0x1.999999999999ap-4, 0x1.999999999999ap-3, -0x1.3333333333333p-2}), 0x1p-55);
  EXPECT_EQ(exact_sum_of({}), 0.0);
  EXPECT_EQ(bits(exact_sum_of({-0.0})), bits(0.0));  // an exact zero is +0
  EXPECT_EQ(exact_sum_of({-3.5, 1.25}), -2.25);
}

TEST(ExactSum, SubnormalsAndTheRoundingOfTies) {
  const double tiny = std::numeric_limits<double>::denorm_min();
  EXPECT_EQ(exact_sum_of({tiny, tiny}), 2 * tiny);
  EXPECT_EQ(exact_sum_of({std::numeric_limits<double>::min(), -tiny}),
            std::nextafter(std::numeric_limits<double>::min(), 0.0));
  EXPECT_EQ(exact_sum_of({1.0, 0x1p-53}), 1.0);                      // a tie: to the even 1
  EXPECT_EQ(exact_sum_of({1.0, 0x1p-53, 0x1p-200}), 1.0 + 0x1p-52);  // just above the tie
  EXPECT_EQ(exact_sum_of({1.0 + 0x1p-52, 0x1p-53}), 1.0 + 0x1p-51);  // a tie: to the even one above
  EXPECT_EQ(exact_sum_of({std::numeric_limits<double>::max(), std::numeric_limits<double>::max()}),
            std::numeric_limits<double>::infinity());
}

TEST(ExactSum, InfinitiesAndNan) {
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(exact_sum_of({1.0, inf}), inf);
  EXPECT_EQ(exact_sum_of({-inf, 1e300}), -inf);
  EXPECT_TRUE(std::isnan(exact_sum_of({inf, -inf})));
  EXPECT_TRUE(std::isnan(exact_sum_of({1.0, std::numeric_limits<double>::quiet_NaN()})));
}

// Random terms m 2^e (m < 2^53, e in [-40, 20]) whose exact sum fits a 128-bit integer in units of 2^-40:
// the reference is that integer, summed apart from the accumulator, converted to double by the compiler's
// correctly rounded conversion and scaled by a power of two.
TEST(ExactSum, MatchesAnIndependentIntegerSumInAnyOrderAndSplit) {
  std::mt19937_64 rng(49);
  for (int trial = 0; trial < 200; ++trial) {
    const std::size_t n = 1 + rng() % 3000;
    std::vector<double> xs(n);
    Int128 total = 0;
    for (auto& x : xs) {
      const auto m = static_cast<std::int64_t>(rng() >> 11);  // < 2^53
      const int e = static_cast<int>(rng() % 61) - 40;
      const bool negative = (rng() & 1) != 0;
      x = std::ldexp(static_cast<double>(m), e) * (negative ? -1 : 1);
      const Int128 units = static_cast<Int128>(m) << (e + 40);
      total += negative ? -units : units;
    }
    const double reference = std::ldexp(static_cast<double>(total), -40);
    const double forward = exact_sum_of(xs);
    ASSERT_EQ(bits(forward), bits(reference)) << "trial " << trial;
    ExactSum terms;  // the loop of the pass driver's blocks
    terms.add_terms(0, n, [&](std::size_t i) { return xs[i]; });
    ASSERT_EQ(bits(terms.value()), bits(reference)) << "trial " << trial;
    // Shuffled and cut into parts summed apart, then merged in a random order: the same bits.
    std::shuffle(xs.begin(), xs.end(), rng);
    const std::size_t parts = 1 + rng() % 7;
    std::vector<ExactSum> acc(parts);
    for (std::size_t i = 0; i < n; ++i) acc[rng() % parts].add(xs[i]);
    std::shuffle(acc.begin(), acc.end(), rng);
    ExactSum merged;
    for (const auto& a : acc) merged.merge(a);
    ASSERT_EQ(bits(merged.value()), bits(reference)) << "trial " << trial;
  }
}

// Beyond the limit of pending additions (2^29) the digits are carried: many equal terms sum exactly.
TEST(ExactSum, ManyTermsCarryWithoutOverflow) {
  ExactSum s;
  const double x = 0x1.fffffffffffffp+1000;  // every digit piece near its largest
  const long n = (1L << 29) + 12345;
  for (long i = 0; i < n; ++i) s.add(x);
  EXPECT_EQ(s.value(), x * static_cast<double>(n));  // the exact n x, rounded once as the product is
}

}  // namespace
}  // namespace cellsph
