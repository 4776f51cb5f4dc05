// The distributed tests' program (CMakeLists.txt: `mpi.np1` ... `mpi.np4`, mpiexec with 1 to 4 ranks). Every
// rank runs every test; a failure on any rank fails its exit code and so mpiexec's. Each test's expected
// values come from a single-process computation of the same thing on every rank (the whole input is made
// from a seed on every rank), not from the distributed code under test.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "cellsph/core/exact_sum.hpp"
#include "cellsph/distributed/communicator.hpp"
#include "cellsph/distributed/curve_split.hpp"

namespace cellsph::distributed {
namespace {

std::uint64_t bits_of(double x) {
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

TEST(Communicator, RanksFromTheLauncher) {
  const auto w = world();
  ASSERT_TRUE(built_with_mpi());
  EXPECT_GE(w.size(), 1);
  EXPECT_GE(w.rank(), 0);
  EXPECT_LT(w.rank(), w.size());
  EXPECT_FALSE(mpi_library_version().empty());
  // Every rank counts itself once.
  std::int64_t one[2] = {1, w.rank()};
  w.sum_in_place(one, 2);
  EXPECT_EQ(one[0], w.size());
  EXPECT_EQ(one[1], std::int64_t{w.size()} * (w.size() - 1) / 2);
  EXPECT_EQ(w.max(double(w.rank())), double(w.size() - 1));
  const auto all = w.all_gather(std::vector<std::int64_t>(static_cast<std::size_t>(w.rank()), w.rank()));
  std::vector<std::int64_t> want;
  for (int r = 0; r < w.size(); ++r) want.insert(want.end(), static_cast<std::size_t>(r), r);
  EXPECT_EQ(all, want);
}

// The terms of a global sum dealt to the ranks in three ways (contiguous, round robin, at random): the
// exact sum over the ranks has the bits of one accumulator over all the terms in order, on every rank.
TEST(Communicator, ExactSumOverRanksHasTheSingleProcessBits) {
  const auto w = world();
  std::mt19937_64 rng(4949);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> terms(20000);
  for (double& t : terms) t = u(rng) * std::pow(10.0, static_cast<int>(rng() % 30) - 15);
  ExactSum whole;
  for (const double t : terms) whole.add(t);
  const double want = whole.value();
  std::vector<int> owner(terms.size());
  for (int way = 0; way < 3; ++way) {
    for (std::size_t i = 0; i < terms.size(); ++i)
      owner[i] = way == 0   ? static_cast<int>(i * std::size_t(w.size()) / terms.size())
                 : way == 1 ? static_cast<int>(i % std::size_t(w.size()))
                            : static_cast<int>(rng() % std::uint64_t(w.size()));
    ExactSum mine;
    for (std::size_t i = terms.size(); i-- > 0;)  // backwards: the order does not matter either
      if (owner[i] == w.rank()) mine.add(terms[i]);
    EXPECT_EQ(bits_of(w.sum(mine).value()), bits_of(want)) << "way " << way << ", rank " << w.rank();
  }
  // A plain double sum in order gives other bits for these terms (the test could fail).
  double plain = 0;
  for (const double t : terms) plain += t;
  EXPECT_NE(bits_of(plain), bits_of(want));
}

// The same particles dealt to the ranks in two ways: the cuts are those one process finds over all of them,
// on every rank (they depend on the keys and weights only, not on who holds them).
TEST(CurveSplitOverRanks, CutsDoNotDependOnWhichRankHoldsWhichParticle) {
  const auto w = world();
  std::mt19937_64 rng(77);
  std::vector<std::uint64_t> keys(30000);
  std::vector<std::int64_t> weight(keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i) {
    keys[i] = i % 3 == 0 ? rng() >> 24 : (std::uint64_t{1} << 20) + (rng() >> 48);  // 40-bit keys, skewed
    weight[i] = 1 + static_cast<std::int64_t>(rng() % 40);
  }
  const auto one = split_curve(keys, weight, 40, 5, 0.001, [](std::int64_t*, int) {});
  for (int way = 0; way < 2; ++way) {
    std::vector<std::uint64_t> mine;
    std::vector<std::int64_t> mine_w;
    for (std::size_t i = 0; i < keys.size(); ++i)
      if (int(way == 0 ? i * std::size_t(w.size()) / keys.size() : i % std::size_t(w.size())) == w.rank()) {
        mine.push_back(keys[i]);
        mine_w.push_back(weight[i]);
      }
    const auto split =
        split_curve(mine, mine_w, 40, 5, 0.001, [&w](std::int64_t* v, int n) { w.sum_in_place(v, n); });
    EXPECT_EQ(split.start, one.start) << "way " << way << ", rank " << w.rank();
  }
}

}  // namespace
}  // namespace cellsph::distributed

int main(int argc, char** argv) {
  cellsph::distributed::MpiSession mpi(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  // Only rank 0 prints GoogleTest's progress; every rank's failures still print and fail its exit code.
  if (cellsph::distributed::world().rank() != 0) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
    listeners.Append(new ::testing::EmptyTestEventListener);
  }
  return RUN_ALL_TESTS();
}
