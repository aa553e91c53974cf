// Piece cost: the estimate of each piece's triangles before any closure, and the plane
// fractions that balance it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include "common/ranked_values.hpp"
#include "stages/generate.hpp"
#include "stages/piece_cost.hpp"
#include "job/pipeline.hpp"
#include "stage_batches.hpp"

namespace partet {
namespace {

PreparedPieces prepared(const SurfaceMesh& input, int k, double density, Balance balance) {
  MeshOptions options;
  options.pieces = k;
  options.density = density;
  options.balance = balance;
  return prepare_pieces(input, options);
}

// RankedValues answers as a sorted copy does: the values below any x (between values, on them,
// outside their range) and every r-th smallest, for spread, clustered, repeated and equal
// values, and for values spanning a range too small or too large for the bucket width.
TEST(RankedValues, AnswersAsASortedCopy) {
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::vector<std::vector<double>> sets(6);
  for (int i = 0; i < 200000; ++i) {
    const double u = unit(random);
    sets[0].push_back(u);
    sets[1].push_back(i % 3 == 0 ? 1e-6 * u : u * u * u * 100);  // most values in a few buckets
    sets[2].push_back(std::round(u * 20) / 20);                     // 41 distinct values
    sets[3].push_back(0.5);
    sets[4].push_back(1 + std::numeric_limits<double>::epsilon() * (i % 7));
    sets[5].push_back(i % 2 ? 1e300 * u : -0.0);
  }
  for (std::size_t s = 0; s < sets.size(); ++s) {
    const RankedValues ranked(sets[s]);
    std::vector<double> sorted = sets[s];
    std::sort(sorted.begin(), sorted.end());
    ASSERT_EQ(ranked.size(), sorted.size());
    std::vector<double> probes = {-2e300, -1, -1e-7, 0, 0.5, 1, 1.5, 2e300};
    for (int i = 0; i < 300; ++i) probes.push_back(sorted[random() % sorted.size()]);
    for (int i = 0; i < 300; ++i) probes.push_back(unit(random));
    for (double x : probes) {
      const auto expected = static_cast<std::size_t>(std::lower_bound(sorted.begin(), sorted.end(), x) - sorted.begin());
      ASSERT_EQ(ranked.count_below(x), expected) << "set " << s << " x " << x;
    }
    for (std::size_t r = 0; r < sorted.size(); r += 97) ASSERT_EQ(ranked.at(r), sorted[r]) << "set " << s << " r " << r;
    ASSERT_EQ(ranked.at(sorted.size() - 1), sorted.back());
  }
}

// The estimate follows the real pieces (input share, split fragments and caps), which the
// closure only builds later: within 15% for each piece of these shapes and cap densities.
TEST(PieceCost, EstimateFollowsTheClosedPieces) {
  for (const char* shape : {"genus3", "torus", "nested"})
    for (double density : {0.0, 0.25, 1.0}) {
      const SurfaceMesh input = generate_surface(shape, 20000);
      const PreparedPieces p = prepared(input, 5, density, Balance::vertices);
      const std::vector<double> estimate = estimated_piece_costs(input, p.planes, density);
      ASSERT_EQ(estimate.size(), p.pieces.size());
      for (std::size_t i = 0; i < estimate.size(); ++i) {
        const auto actual = static_cast<double>(p.pieces[i].triangles.size());
        EXPECT_NEAR(estimate[i] / actual, 1.0, 0.15) << shape << " density " << density << " piece " << i;
      }
    }
}

// The total is the input's triangles plus what each plane adds to both sides.
TEST(PieceCost, NoPlanesIsTheInput) {
  const SurfaceMesh input = generate_surface("torus", 2000);
  EXPECT_EQ(estimated_piece_costs(input, {}, 0.25), std::vector<double>{static_cast<double>(input.triangles.size())});
  EXPECT_EQ(triangles_per_crossing(0), 2);
  EXPECT_EQ(triangles_per_crossing(0.25), 4);
}

// Balanced fractions are increasing, inside (0, 1), and keep the estimated costs within 5% of
// even, where an equal split of the vertices does not (genus3 at K = 6 and 9: 10% and 8%).
TEST(PieceCost, FractionsEvenOutTheEstimate) {
  const SurfaceMesh input = generate_surface("genus3", 20000);
  for (int k : {2, 3, 6, 9}) {
    const Point3 axis = cut_axis(input, CutAxis::coordinate_near_pca);
    const std::vector<double> fractions = cost_balanced_fractions(input, axis, k, 0.25);
    ASSERT_EQ(fractions.size(), static_cast<std::size_t>(k - 1));
    for (std::size_t j = 0; j < fractions.size(); ++j) {
      EXPECT_GT(fractions[j], j == 0 ? 0.0 : fractions[j - 1]);
      EXPECT_LT(fractions[j], 1.0);
    }
    auto spread = [&](const std::vector<double>& cost) {
      const double sum = std::accumulate(cost.begin(), cost.end(), 0.0);
      return *std::max_element(cost.begin(), cost.end()) * static_cast<double>(cost.size()) / sum;
    };
    const double by_vertices = spread(estimated_piece_costs(input, prepared(input, k, 0.25, Balance::vertices).planes, 0.25));
    const double by_cost = spread(estimated_piece_costs(input, prepared(input, k, 0.25, Balance::cost).planes, 0.25));
    // The planes then go to the widest vertex gap near each target, a few percent off it.
    EXPECT_LT(by_cost, 1.05) << k;
    if (by_vertices > 1.05) EXPECT_LT(by_cost, by_vertices) << k;
  }
}

TEST(PieceCost, OnePieceNeedsNoFractions) {
  const SurfaceMesh input = generate_surface("torus", 2000);
  EXPECT_TRUE(cost_balanced_fractions(input, {1, 0, 0}, 1, 0.25).empty());
}

}  // namespace
}  // namespace partet
