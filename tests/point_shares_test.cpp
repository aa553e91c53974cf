// How rank 0 deals its points out to the ranks to format (mpi/point_shares.hpp): every row goes
// to exactly one rank, no rank other than 0 is given more than evens it up, and when the run is
// large enough every rank ends with about as many rows of the section to format.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

#include "mpi/point_shares.hpp"

namespace {

using partet::mpi::point_shares;

std::size_t ceil_mean(std::size_t run, const std::vector<std::size_t>& kept) {
  const std::size_t total = std::accumulate(kept.begin(), kept.end(), run);
  return (total + kept.size() - 1) / kept.size();
}

TEST(PointShares, OneRankFormatsTheWholeRun) {
  EXPECT_EQ(point_shares(5'600'000, {0}), (std::vector<std::size_t>{5'600'000}));
  EXPECT_EQ(point_shares(0, {7}), (std::vector<std::size_t>{0}));
}

TEST(PointShares, TwoRanksEndWithAsManyRows) {
  // Rank 1 keeps 2 rows of the section (its bulks' Steiner points): it is given 4 of the 10.
  EXPECT_EQ(point_shares(10, {0, 2}), (std::vector<std::size_t>{6, 4}));
  // As at 10.9M faces on 2 ranks: rank 1 keeps about 0.1M rows, the run is 5.6M.
  const auto shares = point_shares(5'600'000, {0, 100'000});
  EXPECT_EQ(shares[0] + shares[1], 5'600'000u);
  EXPECT_EQ(shares[0], shares[1] + 100'000);
}

TEST(PointShares, ARankKeepingMoreThanItsShareIsGivenNothing) {
  EXPECT_EQ(point_shares(10, {0, 20, 0}), (std::vector<std::size_t>{0, 0, 10}));
}

TEST(PointShares, EveryRowGoesToOneRankAndTheLoadsAreEven) {
  std::mt19937_64 random(20261129);
  for (int trial = 0; trial < 2000; ++trial) {
    const std::size_t ranks = 1 + random() % 9;
    std::vector<std::size_t> kept(ranks);
    for (auto& k : kept) k = random() % 4 == 0 ? 0 : random() % 1000;
    const std::size_t run = random() % 5000;
    const auto shares = point_shares(run, kept);
    ASSERT_EQ(shares.size(), ranks);
    ASSERT_EQ(std::accumulate(shares.begin(), shares.end(), std::size_t{0}), run);
    const std::size_t each = ceil_mean(run, kept);
    for (std::size_t r = 1; r < ranks; ++r) {
      ASSERT_LE(kept[r] + shares[r], std::max(each, kept[r])) << "rank " << r << " was given more than evens it up";
      if (kept[r] >= each) ASSERT_EQ(shares[r], 0u);
    }
    // A run that fills every other rank up to the mean leaves rank 0 at most the mean, and at
    // least the mean less one row per rank (the mean is rounded up).
    std::size_t gaps = 0;
    for (std::size_t r = 1; r < ranks; ++r) gaps += each > kept[r] ? each - kept[r] : 0;
    if (run >= gaps && std::all_of(kept.begin() + 1, kept.end(), [&](std::size_t k) { return k <= each; })) {
      ASSERT_LE(kept[0] + shares[0], each);
      ASSERT_GE(kept[0] + shares[0] + ranks, each + 1);
    }
  }
}

}  // namespace
