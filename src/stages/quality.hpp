// Element quality: conformal AMIPS energy, dihedral angles (with TetGen's histogram bins) and
// radius-edge ratios, for a whole mesh or a part of it (e.g. the tets along the seams).
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "partet/mesh_types.hpp"
#include "stages/partition.hpp"

namespace partet {

// The upper ends of TetGen's dihedral angle histogram bins, degrees (the first starts at 0).
constexpr std::array<double, 17> kDihedralBins = {5,   10,  30,  40,  50,  60,  70,  80, 110,
                                                  120, 130, 140, 150, 160, 170, 175, 180};

struct MeshQuality {
  std::int64_t tets = 0;
  double amips_avg = 0, amips_p99 = 0, amips_max = 0;  // conformal AMIPS energy, 3 = regular tet
  double min_dihedral_deg = 0, max_dihedral_deg = 0;
  std::int64_t below_5deg = 0, above_175deg = 0;  // tets with a dihedral angle < 5 or > 175 deg
  double radius_edge_avg = 0, radius_edge_max = 0;  // circumradius / shortest edge (0.612 regular)
  std::int64_t radius_edge_above_2 = 0;             // tets TetGen's default -q would refine
  std::array<std::int64_t, kDihedralBins.size()> dihedral_histogram{};  // all six angles of every tet
};

// The quality of the tets for which `include(t)` holds (all when empty).
MeshQuality mesh_quality(const TetMesh& mesh, const std::function<bool(std::size_t)>& include = {});

// The same figures, tallied one tet at a time: for a mesh held in parts (the check on several
// ranks tallies each rank's tets, then adds the counts and sums, takes the extremes, and finds the
// 99th percentile among every rank's AMIPS values).
struct QualityTally {
  std::int64_t tets = 0, below_5deg = 0, above_175deg = 0, radius_edge_above_2 = 0;
  std::array<std::int64_t, kDihedralBins.size()> dihedral_histogram{};
  long double amips_sum = 0, radius_edge_sum = 0;
  double amips_max = 0, radius_edge_max = 0;
  double largest_cos = -1, smallest_cos = 1;  // of the dihedral angles seen
  std::vector<float> amips;                   // every tet's (flat and inverted ones: 3e38), for the percentile

  void add(const Point3& a, const Point3& b, const Point3& c, const Point3& d);
  // The figures, given the 99th percentile of the AMIPS values (the amips_p99_rank-th smallest).
  MeshQuality figures(double amips_p99) const;
};
// Which of `tets` sorted values is the 99th percentile (from 0).
std::int64_t amips_p99_rank(std::int64_t tets);

// Conformal AMIPS energy tr(J^T J) / det(J)^(2/3) of one tet (3 for a regular tet, +inf for a
// flat or inverted one).
double amips_energy(const Point3& a, const Point3& b, const Point3& c, const Point3& d);

// The two measures by which the polish picks its tets: the AMIPS energy and the smallest
// dihedral angle (degrees; 0 for a flat or degenerate tet).
struct TetShape {
  double amips;
  double min_dihedral_deg;
};
TetShape tet_shape(const Point3& a, const Point3& b, const Point3& c, const Point3& d);

// The least AMIPS energy of a tet with a dihedral angle below `dihedral_deg` (or above 180 deg
// minus it): such a tet is the regular tet (face normals 70.53 deg apart as lines) under a map
// of condition number k >= tan(35.26 deg) / tan(dihedral / 2), and AMIPS >= 1.5 cbrt(2)
// ((k^2 + 1) / k)^(2/3). Lets a scan skip the dihedral angles of tets below this energy
// (12.1 for 5 deg).
double amips_lower_bound(double dihedral_deg);

// The seam zone: the tets that cross or touch a cut plane (where two pieces met). The planes
// are parallel and sorted by offset.
std::vector<char> seam_zone(const TetMesh& mesh, const std::vector<CutPlane>& planes);
bool in_seam_zone(const std::vector<CutPlane>& planes, const Point3& a, const Point3& b, const Point3& c,
                  const Point3& d);

// The quality of the seam zone and of the rest (the report, and `partet check --report`).
struct ZoneQuality {
  MeshQuality seam, elsewhere;
};
ZoneQuality zone_quality(const TetMesh& mesh, const std::vector<CutPlane>& planes);

}  // namespace partet
