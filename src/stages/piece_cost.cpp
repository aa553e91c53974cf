#include "stages/piece_cost.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "common/parallel.hpp"
#include "common/ranked_values.hpp"
#include "stages/geometry.hpp"

namespace partet {
namespace {

double centroid(const std::vector<double>& proj, const Triangle& t) {
  return (proj[t[0]] + proj[t[1]] + proj[t[2]]) / 3;
}

// Each edge of a closed oriented surface once: where it runs from the lower id to the higher
// (it runs the other way in its other triangle).
template <class F>
void for_each_edge(const Triangle& t, F f) {
  for (int e = 0; e < 3; ++e)
    if (t[e] < t[(e + 1) % 3]) f(t[e], t[(e + 1) % 3]);
}

// Each vertex's position along the axis.
std::vector<double> projections(const SurfaceMesh& surface, const Point3& axis) {
  std::vector<double> proj(surface.points.size());
  for (std::size_t i = 0; i < surface.points.size(); ++i) proj[i] = dot(axis, surface.points[i]);
  return proj;
}

// The triangles' centroids along the axis.
std::vector<double> centroids_along(const SurfaceMesh& surface, const std::vector<double>& proj) {
  std::vector<double> centroids;
  centroids.reserve(surface.triangles.size());
  for (const Triangle& t : surface.triangles) centroids.push_back(centroid(proj, t));
  return centroids;
}

// The input along the cut axis: where its triangles, edges and vertices lie.
class AxisProfile {
 public:
  AxisProfile(const SurfaceMesh& surface, const AxisVertices& along)
      : AxisProfile(surface, along, projections(surface, along.axis)) {}

  double triangles() const { return static_cast<double>(centroids_.size()); }
  double triangles_below(double x) const { return static_cast<double>(centroids_.count_below(x)); }
  // Input edges a plane at x crosses (low < x <= high).
  double crossings(double x) const {
    const auto below = vertices_below(x);
    return static_cast<double>(starts_below_[below] - ends_below_[below]);
  }
  // The position with `count` triangle centroids below it (between two centroids).
  double position_of(double count) const {
    const auto m = centroids_.size();
    const auto r = static_cast<std::size_t>(std::clamp(std::round(count), 1.0, static_cast<double>(m - 1)));
    return (centroids_.at(r - 1) + centroids_.at(r)) / 2;
  }
  double vertex_fraction_below(double x) const {
    return static_cast<double>(vertices_below(x)) / static_cast<double>(along_.sorted.size());
  }
  double vertex_quantile(double fraction) const {
    const auto n = along_.sorted.size();
    const auto r = static_cast<std::size_t>(
        std::clamp(std::round(fraction * static_cast<double>(n)), 1.0, static_cast<double>(n - 1)));
    return (along_.sorted[r - 1].first + along_.sorted[r].first) / 2;
  }
  bool usable(int k) const { return along_.sorted.size() > static_cast<std::size_t>(k) && centroids_.size() > 2; }

 private:
  AxisProfile(const SurfaceMesh& surface, const AxisVertices& along, const std::vector<double>& proj)
      : along_(along), centroids_(centroids_along(surface, proj)) {
    // An edge is counted at its lower and at its upper end, so the edges below a position are
    // found from the vertices below it: no sort of the edges (twice as many values).
    std::vector<std::array<std::int32_t, 2>> ends(surface.points.size(), {0, 0});  // edges starting, ending here
    for (const Triangle& t : surface.triangles)
      for_each_edge(t, [&](std::int32_t a, std::int32_t b) {
        const bool a_low = proj[a] < proj[b] || (proj[a] == proj[b] && a < b);
        ++ends[a_low ? a : b][0];
        ++ends[a_low ? b : a][1];
      });
    const std::size_t n = along.sorted.size();
    starts_below_.resize(n + 1), ends_below_.resize(n + 1);
    starts_below_[0] = ends_below_[0] = 0;
    for (std::size_t r = 0; r < n; ++r) {
      // The vertices come in axis order, their counts in id order: fetch ahead (memory latency).
      if (r + 16 < n) __builtin_prefetch(&ends[along.sorted[r + 16].second]);
      const auto& counted = ends[along.sorted[r].second];
      starts_below_[r + 1] = starts_below_[r] + counted[0];
      ends_below_[r + 1] = ends_below_[r] + counted[1];
    }
  }

  std::size_t vertices_below(double x) const {
    return static_cast<std::size_t>(
        std::lower_bound(along_.sorted.begin(), along_.sorted.end(), x,
                         [](const std::pair<double, std::size_t>& v, double y) { return v.first < y; }) -
        along_.sorted.begin());
  }
  const AxisVertices& along_;  // the vertices in axis order
  RankedValues centroids_;
  // Edges whose lower (upper) end is among the first i sorted vertices.
  std::vector<std::int64_t> starts_below_, ends_below_;
};

// Cost of each piece between consecutive positions.
std::vector<double> piece_costs(const AxisProfile& profile, const std::vector<double>& positions, double per_crossing) {
  std::vector<double> cost;
  double below = 0;
  for (std::size_t j = 0; j <= positions.size(); ++j) {
    const double upto = j < positions.size() ? profile.triangles_below(positions[j]) : profile.triangles();
    cost.push_back(upto - below);
    below = upto;
  }
  for (std::size_t j = 0; j < positions.size(); ++j) {
    const double sides = per_crossing * profile.crossings(positions[j]);
    cost[j] += sides;
    cost[j + 1] += sides;
  }
  return cost;
}

// One step: with the caps measured at the current positions, the positions that make every
// piece's input share plus its caps equal. Empty when a piece's caps alone exceed most of it.
std::vector<double> equalized(const AxisProfile& profile, const std::vector<double>& positions, double per_crossing) {
  const std::size_t k = positions.size() + 1;
  std::vector<double> cap(k + 1, 0);  // cap[j + 1]: what plane j adds to each side
  double total = profile.triangles();
  for (std::size_t j = 0; j < positions.size(); ++j) {
    cap[j + 1] = per_crossing * profile.crossings(positions[j]);
    total += 2 * cap[j + 1];
  }
  const double each = total / static_cast<double>(k);
  std::vector<double> next;
  double below = 0;
  for (std::size_t i = 0; i + 1 < k; ++i) {
    const double share = each - cap[i] - cap[i + 1];
    if (share < 0.1 * each) return {};
    below += share;
    next.push_back(profile.position_of(below));
  }
  return next;
}

}  // namespace

double triangles_per_crossing(double density) { return 2 + 8 * std::max(density, 0.0); }

std::vector<double> estimated_piece_costs(const SurfaceMesh& surface, const std::vector<CutPlane>& planes,
                                          double density) {
  // One pass, no sorting (a report asks for this at the end of a run): counted exactly as
  // AxisProfile counts at the planes' offsets.
  std::vector<double> offsets;
  for (const CutPlane& p : planes) offsets.push_back(p.offset);
  const Point3 axis = planes.empty() ? Point3{1, 0, 0} : planes.front().normal;
  const std::vector<double> proj = projections(surface, axis);
  // Whole counts per run of the triangles, on every usable CPU (the end of a run waits for this):
  // their sums do not depend on how the triangles were divided.
  const std::size_t runs = std::max<std::size_t>(1, std::min<std::size_t>(64, surface.triangles.size() >> 16));
  std::vector<std::vector<std::int64_t>> counted(runs, std::vector<std::int64_t>(2 * planes.size() + 1, 0));
  parallel_for(runs, usable_cpus(), [&](std::size_t r) {
    std::int64_t* in_piece = counted[r].data();
    std::int64_t* crossing = in_piece + planes.size() + 1;
    const std::size_t n = surface.triangles.size();
    for (std::size_t f = n * r / runs; f < n * (r + 1) / runs; ++f) {
      const Triangle& t = surface.triangles[f];
      ++in_piece[std::upper_bound(offsets.begin(), offsets.end(), centroid(proj, t)) - offsets.begin()];
      for_each_edge(t, [&](std::int32_t a, std::int32_t b) {
        const auto [low, high] = std::minmax(proj[a], proj[b]);
        for (auto j = std::upper_bound(offsets.begin(), offsets.end(), low); j != offsets.end() && *j <= high; ++j)
          ++crossing[j - offsets.begin()];
      });
    }
  });
  std::vector<double> cost(planes.size() + 1, 0), crossings(planes.size(), 0);
  for (const auto& run : counted) {
    for (std::size_t j = 0; j <= planes.size(); ++j) cost[j] += static_cast<double>(run[j]);
    for (std::size_t j = 0; j < planes.size(); ++j) crossings[j] += static_cast<double>(run[planes.size() + 1 + j]);
  }
  const double per_crossing = triangles_per_crossing(density);
  for (std::size_t j = 0; j < planes.size(); ++j) {
    cost[j] += per_crossing * crossings[j];
    cost[j + 1] += per_crossing * crossings[j];
  }
  return cost;
}

std::vector<double> cost_balanced_fractions(const SurfaceMesh& surface, const Point3& axis, int k, double density) {
  if (k < 2) return {};
  return cost_balanced_fractions(surface, sort_vertices_along(surface, axis), k, density);
}

std::vector<double> cost_balanced_fractions(const SurfaceMesh& surface, const AxisVertices& along, int k,
                                            double density) {
  if (k < 2) return {};
  const AxisProfile profile(surface, along);
  if (!profile.usable(k)) return {};
  const double per_crossing = triangles_per_crossing(density);
  auto largest_ratio = [&](const std::vector<double>& positions) {
    const std::vector<double> cost = piece_costs(profile, positions, per_crossing);
    double sum = 0;
    for (double c : cost) sum += c;
    return *std::max_element(cost.begin(), cost.end()) * static_cast<double>(cost.size()) / sum;
  };
  // From the equal split of the vertices, a few steps (the caps change where the planes move),
  // keeping the best estimate.
  std::vector<double> positions;
  for (int j = 1; j < k; ++j) positions.push_back(profile.vertex_quantile(static_cast<double>(j) / k));
  std::vector<double> best = positions;
  double best_ratio = largest_ratio(positions);
  for (int step = 0; step < 4; ++step) {
    positions = equalized(profile, positions, per_crossing);
    if (positions.empty()) break;
    const double ratio = largest_ratio(positions);
    if (ratio < best_ratio) best = positions, best_ratio = ratio;
  }
  std::vector<double> fractions;
  for (double x : best) fractions.push_back(profile.vertex_fraction_below(x));
  // choose_cut_planes needs increasing fractions inside (0, 1).
  for (std::size_t j = 0; j < fractions.size(); ++j)
    if (!(fractions[j] > 0 && fractions[j] < 1) || (j > 0 && !(fractions[j] > fractions[j - 1]))) return {};
  return fractions;
}

}  // namespace partet
