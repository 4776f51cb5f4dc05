#include <gtest/gtest.h>

#include <vector>

#include "cellsph/neighbors/neighbor_search.hpp"

namespace cellsph {
namespace {

TEST(AllPairs, FindsPairsWithinPerParticleSupport) {
  // Three points on a line; h differs, so the relation is asymmetric.
  std::vector<Vec<2, double>> x = {{{0.0, 0.0}}, {{1.0, 0.0}}, {{3.0, 0.0}}};
  std::vector<double> h = {1.0, 2.0, 1.5};
  NeighborSearch<2, double> ns({.method = Method::AllPairs});
  ns.build(x, h);
  NeighborList nl;
  ns.find_all(nl);
  ASSERT_EQ(nl.size(), 3u);
  EXPECT_EQ(std::vector<std::uint32_t>(nl.begin(0), nl.end(0)), (std::vector<std::uint32_t>{1}));
  EXPECT_EQ(std::vector<std::uint32_t>(nl.begin(1), nl.end(1)), (std::vector<std::uint32_t>{0, 2}));
  EXPECT_TRUE(nl.count(2) == 0);
  EXPECT_EQ(ns.stats().pairs, 3u);
}

}  // namespace
}  // namespace cellsph
