#include "stages/quality.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "stages/geometry.hpp"

namespace partet {
namespace {

// The measures of one tet.
struct TetMeasures {
  double amips;
  double largest_cos, smallest_cos;  // of its dihedral angles (the smallest angle has the largest)
  double cos[6];                     // every dihedral angle's cosine
  bool degenerate;                   // a face without area: angles undefined
  double radius_edge;
};

double signed_volume6(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  return dot(sub(b, a), cross(sub(c, a), sub(d, a)));
}

// Dihedral angles from consistently oriented face normals: the angle at the edge shared by faces
// i and j is pi minus the angle between their normals.
void dihedral_cosines(const Point3* p[4], TetMeasures& m) {
  Point3 normal[4];
  double length[4];
  for (int j = 0; j < 4; ++j) {
    const Triangle f = outward_face(Tet{0, 1, 2, 3}, j);
    normal[j] = cross(sub(*p[f[1]], *p[f[0]]), sub(*p[f[2]], *p[f[0]]));
    length[j] = norm(normal[j]);
  }
  m.largest_cos = -1;
  m.smallest_cos = 1;
  m.degenerate = false;
  int k = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j, ++k) {
      if (!(length[i] > 0 && length[j] > 0)) {
        m.degenerate = true;
        m.cos[k] = 1;
        continue;
      }
      m.cos[k] = std::clamp(-dot(normal[i], normal[j]) / (length[i] * length[j]), -1.0, 1.0);
      m.largest_cos = std::max(m.largest_cos, m.cos[k]);
      m.smallest_cos = std::min(m.smallest_cos, m.cos[k]);
    }
  // A face without area has no defined angles: count it as both extremes.
  if (m.degenerate) m.largest_cos = 1, m.smallest_cos = -1;
}

// Circumradius over the shortest edge.
double radius_edge_ratio(const Point3* p[4]) {
  const Point3 a = sub(*p[1], *p[0]), b = sub(*p[2], *p[0]), c = sub(*p[3], *p[0]);
  const double det = 2 * dot(a, cross(b, c));
  if (det == 0) return std::numeric_limits<double>::infinity();
  Point3 center = cross(b, c);
  for (int i = 0; i < 3; ++i) center[i] *= dot(a, a);
  const Point3 cb = cross(c, a), ab = cross(a, b);
  for (int i = 0; i < 3; ++i) center[i] = (center[i] + cb[i] * dot(b, b) + ab[i] * dot(c, c)) / det;
  double shortest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) shortest = std::min(shortest, distance(*p[i], *p[j]));
  return norm(center) / shortest;
}

// Bins by cosine (decreasing with the angle), without an acos per angle.
void add_to_histogram(const TetMeasures& m, std::array<std::int64_t, kDihedralBins.size()>& histogram) {
  static const auto kBinCos = [] {
    std::array<double, kDihedralBins.size()> c{};
    for (std::size_t i = 0; i < c.size(); ++i) c[i] = std::cos(kDihedralBins[i] * kPi / 180);
    return c;
  }();
  for (double c : m.cos) {
    std::size_t bin = 0;
    while (bin + 1 < kBinCos.size() && c <= kBinCos[bin]) ++bin;
    ++histogram[bin];
  }
}

}  // namespace

double amips_energy(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  // J = M * W^-1, with M = [b-a, c-a, d-a] and W the same matrix for the unit regular tet
  // a=0, b=(1,0,0), c=(1/2, sqrt3/2, 0), d=(1/2, sqrt3/6, sqrt(2/3)). W^-1 is upper triangular:
  //   [1, -1/sqrt3, -1/sqrt6; 0, 2/sqrt3, -1/sqrt6; 0, 0, sqrt(3/2)]
  // so J's columns are m0, (2 m1 - m0)/sqrt3, (3 m2 - m0 - m1)/sqrt6, and det J = sqrt2 det M.
  static const double kInvSqrt3 = 1 / std::sqrt(3.0), kInvSqrt6 = 1 / std::sqrt(6.0), kSqrt2 = std::sqrt(2.0);
  const Point3 m0 = sub(b, a), m1 = sub(c, a), m2 = sub(d, a);
  const double det_m = signed_volume6(a, b, c, d);
  if (!(det_m > 0)) return std::numeric_limits<double>::infinity();
  double trace = 0;
  for (int k = 0; k < 3; ++k) {
    const double j0 = m0[k];
    const double j1 = (2 * m1[k] - m0[k]) * kInvSqrt3;
    const double j2 = (3 * m2[k] - m0[k] - m1[k]) * kInvSqrt6;
    trace += j0 * j0 + j1 * j1 + j2 * j2;
  }
  const double det_j = kSqrt2 * det_m;
  return trace / std::cbrt(det_j * det_j);
}

TetShape tet_shape(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  const Point3* p[4] = {&a, &b, &c, &d};
  TetMeasures m{};
  dihedral_cosines(p, m);
  return {amips_energy(a, b, c, d), std::acos(m.largest_cos) * 180 / kPi};
}

double amips_lower_bound(double dihedral_deg) {
  if (!(dihedral_deg > 0)) return std::numeric_limits<double>::infinity();
  const double half_regular = std::atan(std::sqrt(0.5));  // half of acos(1/3), the regular tet's angle
  const double k = std::tan(half_regular) / std::tan(std::min(dihedral_deg, 70.0) * kPi / 360);
  return 1.5 * std::cbrt(2.0) * std::pow((k * k + 1) / k, 2.0 / 3.0);
}

void QualityTally::add(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  static const double kCos5 = std::cos(5 * kPi / 180), kCos175 = std::cos(175 * kPi / 180);
  const Point3* p[4] = {&a, &b, &c, &d};
  TetMeasures m{};
  m.amips = amips_energy(a, b, c, d);
  dihedral_cosines(p, m);
  m.radius_edge = radius_edge_ratio(p);
  ++tets;
  amips_sum += m.amips;
  amips.push_back(m.amips < 3.0e38 ? static_cast<float>(m.amips) : 3.0e38f);  // NaN too
  amips_max = std::max(amips_max, m.amips);
  largest_cos = std::max(largest_cos, m.largest_cos);
  smallest_cos = std::min(smallest_cos, m.smallest_cos);
  if (m.largest_cos > kCos5) ++below_5deg;
  if (m.smallest_cos < kCos175) ++above_175deg;
  radius_edge_sum += m.radius_edge;
  radius_edge_max = std::max(radius_edge_max, m.radius_edge);
  if (m.radius_edge > 2) ++radius_edge_above_2;
  add_to_histogram(m, dihedral_histogram);
}

MeshQuality QualityTally::figures(double amips_p99) const {
  MeshQuality q;
  q.tets = tets;
  if (tets == 0) return q;
  q.amips_avg = static_cast<double>(amips_sum / tets);
  q.amips_p99 = amips_p99;
  q.amips_max = amips_max;
  q.min_dihedral_deg = std::acos(largest_cos) * 180 / kPi;
  q.max_dihedral_deg = std::acos(smallest_cos) * 180 / kPi;
  q.below_5deg = below_5deg;
  q.above_175deg = above_175deg;
  q.radius_edge_avg = static_cast<double>(radius_edge_sum / tets);
  q.radius_edge_max = radius_edge_max;
  q.radius_edge_above_2 = radius_edge_above_2;
  q.dihedral_histogram = dihedral_histogram;
  return q;
}

std::int64_t amips_p99_rank(std::int64_t tets) {
  return tets > 0 ? static_cast<std::int64_t>(0.99 * static_cast<double>(tets - 1)) : 0;
}

MeshQuality mesh_quality(const TetMesh& mesh, const std::function<bool(std::size_t)>& include) {
  QualityTally tally;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    if (include && !include(t)) continue;
    const Tet& tet = mesh.tets[t];
    tally.add(mesh.points[tet[0]], mesh.points[tet[1]], mesh.points[tet[2]], mesh.points[tet[3]]);
  }
  if (tally.tets == 0) return tally.figures(0);
  const auto rank99 = static_cast<std::size_t>(amips_p99_rank(tally.tets));
  std::nth_element(tally.amips.begin(), tally.amips.begin() + static_cast<long>(rank99), tally.amips.end());
  return tally.figures(tally.amips[rank99]);
}

bool in_seam_zone(const std::vector<CutPlane>& planes, const Point3& a, const Point3& b, const Point3& c,
                  const Point3& d) {
  if (planes.empty()) return false;
  const Point3& n = planes.front().normal;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Point3* p : {&a, &b, &c, &d}) {
    const double x = dot(n, *p);
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  // Planes are sorted by offset: is one in [lo, hi]?
  auto it = std::lower_bound(planes.begin(), planes.end(), lo,
                             [](const CutPlane& plane, double x) { return plane.offset < x; });
  return it != planes.end() && it->offset <= hi;
}

std::vector<char> seam_zone(const TetMesh& mesh, const std::vector<CutPlane>& planes) {
  std::vector<char> zone(mesh.tets.size(), 0);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const Tet& tet = mesh.tets[t];
    zone[t] = in_seam_zone(planes, mesh.points[tet[0]], mesh.points[tet[1]], mesh.points[tet[2]],
                           mesh.points[tet[3]]);
  }
  return zone;
}

ZoneQuality zone_quality(const TetMesh& mesh, const std::vector<CutPlane>& planes) {
  const std::vector<char> zone = seam_zone(mesh, planes);
  return {mesh_quality(mesh, [&](std::size_t t) { return zone[t] != 0; }),
          mesh_quality(mesh, [&](std::size_t t) { return zone[t] == 0; })};
}

}  // namespace partet
