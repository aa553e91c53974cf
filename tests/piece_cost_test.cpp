// Piece cost: the estimate of each piece's triangles before any closure, and the plane
// fractions that balance it.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <vector>

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
