// Independent verification of a tet mesh: recomputes everything from points and tets only. It
// keeps its own orientation determinant and exact predicate on purpose: the check must not
// share code with what it verifies (the mesher's orientation vote, the merge's welding).
#include "stages/check.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

#include "stages/geometry.hpp"
#include "stages/topology.hpp"
#include "stages/validate.hpp"

namespace partet {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

constexpr double kVolumeTolerance = kCheckVolumeTolerance;

std::string format_number(double x) {
  char text[40];
  std::snprintf(text, sizeof text, "%.15g", x);
  return text;
}

std::string format_triangle(const Triangle& t) {
  return "(" + std::to_string(t[0]) + ", " + std::to_string(t[1]) + ", " + std::to_string(t[2]) + ")";
}

// Rotates an oriented triangle so its smallest index comes first; orientation is kept, so
// (a,b,c) and (a,c,b) stay different.
Triangle normalized(const Triangle& t) {
  if (t[1] < t[0] && t[1] < t[2]) return {t[1], t[2], t[0]};
  if (t[2] < t[0] && t[2] < t[1]) return {t[2], t[0], t[1]};
  return t;
}

Triangle reversed(const Triangle& t) { return normalized({t[0], t[2], t[1]}); }

// Counting-sort offsets of items bucketed by a vertex: bucketing by the smallest vertex and
// sorting the small buckets is linear and much faster than a global hash map at millions of tets.
template <class BucketOf>
std::vector<std::uint32_t> bucket_offsets(std::size_t item_count, std::size_t vertex_count, BucketOf bucket_of) {
  std::vector<std::uint32_t> start(vertex_count + 1, 0);
  for (std::size_t i = 0; i < item_count; ++i) ++start[bucket_of(i) + 1];
  for (std::size_t v = 0; v < vertex_count; ++v) start[v + 1] += start[v];
  return start;
}

// Number of distinct edges of the tets.
std::int64_t count_edges(const std::vector<Tet>& tets, std::size_t vertex_count) {
  static constexpr int kEdge[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  std::size_t edge_count = tets.size() * 6;
  auto low = [&](std::size_t i) {
    const Tet& t = tets[i / 6];
    return std::min(t[kEdge[i % 6][0]], t[kEdge[i % 6][1]]);
  };
  auto start = bucket_offsets(edge_count, vertex_count, low);
  std::vector<std::int32_t> high(edge_count);
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  for (std::size_t i = 0; i < edge_count; ++i) {
    const Tet& t = tets[i / 6];
    std::int32_t a = t[kEdge[i % 6][0]], b = t[kEdge[i % 6][1]];
    high[fill[std::min(a, b)]++] = std::max(a, b);
  }
  std::int64_t distinct = 0;
  for (std::size_t v = 0; v < vertex_count; ++v) {
    auto first = high.begin() + start[v], last = high.begin() + start[v + 1];
    std::sort(first, last);
    distinct += std::unique(first, last) - first;
  }
  return distinct;
}

// Exact coordinates as a sortable key. Adding 0.0 turns -0.0 into +0.0, which is the same point.
struct CoordinateKey {
  std::uint64_t bits[3];
  bool operator<(const CoordinateKey& o) const {
    return std::lexicographical_compare(bits, bits + 3, o.bits, o.bits + 3);
  }
  bool operator==(const CoordinateKey& o) const { return std::equal(bits, bits + 3, o.bits); }
};

CoordinateKey coordinate_key(const Point3& p) {
  CoordinateKey key;
  for (int k = 0; k < 3; ++k) {
    double x = p[k] + 0.0;
    std::memcpy(&key.bits[k], &x, sizeof x);
  }
  return key;
}

struct KeyedVertex {
  CoordinateKey key;
  std::int32_t index;
  bool operator<(const KeyedVertex& o) const { return key == o.key ? index < o.index : key < o.key; }
};

// In long double: the products of three coordinate differences underflow double for inputs at
// scale 1e-110 and below.
long double signed_volume6_precise(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  long double u[3], v[3], w[3];
  for (int k = 0; k < 3; ++k) {
    u[k] = static_cast<long double>(b[k]) - a[k];
    v[k] = static_cast<long double>(c[k]) - a[k];
    w[k] = static_cast<long double>(d[k]) - a[k];
  }
  return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
}

}  // namespace

long surface_euler_characteristic(const SurfaceMesh& surface) {
  std::vector<char> used(surface.points.size(), 0);
  std::vector<std::uint64_t> edges;
  edges.reserve(surface.triangles.size() * 3);
  for (const Triangle& t : surface.triangles)
    for (int k = 0; k < 3; ++k) {
      std::int32_t a = t[k], b = t[(k + 1) % 3];
      if (a >= 0 && static_cast<std::size_t>(a) < used.size()) used[a] = 1;
      if (a > b) std::swap(a, b);
      edges.push_back(static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32 | static_cast<std::uint32_t>(b));
    }
  std::sort(edges.begin(), edges.end());
  long edge_count = std::unique(edges.begin(), edges.end()) - edges.begin();
  long vertex_count = std::count(used.begin(), used.end(), 1);
  return vertex_count - edge_count + static_cast<long>(surface.triangles.size());
}

int tet_orientation(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  return static_cast<int>(CGAL::orientation(Kernel::Point_3(a[0], a[1], a[2]), Kernel::Point_3(b[0], b[1], b[2]),
                                            Kernel::Point_3(c[0], c[1], c[2]), Kernel::Point_3(d[0], d[1], d[2])));
}

long double tet_volume6(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  return signed_volume6_precise(a, b, c, d);
}

namespace {

using Violations = std::vector<std::string>;

// Everything else indexes points through tets, so bad indices end the check.
bool check_indices(const TetMesh& mesh, Violations& violations) {
  std::int64_t bad = 0, first = -1;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    for (std::int32_t v : mesh.tets[t])
      if (v < 0 || static_cast<std::size_t>(v) >= mesh.points.size()) {
        if (bad++ == 0) first = static_cast<std::int64_t>(t);
        break;
      }
  if (bad > 0)
    violations.push_back(std::to_string(bad) + " tets have vertex indices out of range, first: tet " +
                         std::to_string(first));
  return bad == 0;
}

// Orientation, with an exact predicate: a nearly flat tet must not pass by rounding. Returns the
// total tet volume (long double: it does not underflow at any input's scale).
long double check_orientation(const TetMesh& mesh, Violations& violations) {
  std::int64_t negative = 0, flat = 0, first = -1;
  long double volume6 = 0;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const Tet& tet = mesh.tets[t];
    const Point3 &a = mesh.points[tet[0]], &b = mesh.points[tet[1]], &c = mesh.points[tet[2]], &d = mesh.points[tet[3]];
    CGAL::Orientation o = CGAL::orientation(Kernel::Point_3(a[0], a[1], a[2]), Kernel::Point_3(b[0], b[1], b[2]),
                                            Kernel::Point_3(c[0], c[1], c[2]), Kernel::Point_3(d[0], d[1], d[2]));
    if (o != CGAL::POSITIVE) {
      if (negative + flat == 0) first = static_cast<std::int64_t>(t);
      (o == CGAL::NEGATIVE ? negative : flat)++;
    }
    volume6 += signed_volume6_precise(a, b, c, d);
  }
  if (negative + flat > 0)
    violations.push_back(std::to_string(negative + flat) + " tets are not positively oriented (" +
                         std::to_string(negative) + " inverted, " + std::to_string(flat) + " flat), first: tet " +
                         std::to_string(first));
  return volume6 / 6;
}

// Vertices in no tet. Returns the number of used vertices.
std::int64_t check_unused_vertices(const TetMesh& mesh, Violations& violations) {
  std::vector<char> used(mesh.points.size(), 0);
  for (const Tet& t : mesh.tets)
    for (std::int32_t v : t) used[v] = 1;
  const std::int64_t used_count = std::count(used.begin(), used.end(), 1);
  if (used_count < static_cast<std::int64_t>(mesh.points.size())) {
    std::size_t first = std::find(used.begin(), used.end(), 0) - used.begin();
    violations.push_back(std::to_string(mesh.points.size() - used_count) + " vertices are in no tet, first: vertex " +
                         std::to_string(first));
  }
  return used_count;
}

// Vertices with identical coordinates. Returns the vertices sorted by coordinates, used to find
// input vertices in the mesh.
std::vector<KeyedVertex> check_duplicate_vertices(const TetMesh& mesh, Violations& violations) {
  std::vector<KeyedVertex> by_coordinates(mesh.points.size());
  for (std::size_t v = 0; v < mesh.points.size(); ++v)
    by_coordinates[v] = {coordinate_key(mesh.points[v]), static_cast<std::int32_t>(v)};
  std::sort(by_coordinates.begin(), by_coordinates.end());
  std::int64_t duplicates = 0;
  std::int32_t first_a = -1, first_b = -1;
  for (std::size_t i = 1; i < by_coordinates.size(); ++i)
    if (by_coordinates[i].key == by_coordinates[i - 1].key && duplicates++ == 0) {
      first_a = by_coordinates[i - 1].index;
      first_b = by_coordinates[i].index;
    }
  if (duplicates > 0)
    violations.push_back(std::to_string(duplicates) + " duplicate vertices (identical coordinates), first: vertices " +
                         std::to_string(first_a) + " and " + std::to_string(first_b));
  return by_coordinates;
}

struct FaceCount {
  std::vector<Triangle> boundary;  // faces in one tet, oriented out of it
  std::int64_t faces = 0;          // distinct triangles
};

// Counts the tets on each triangle: at most two, on opposite sides.
FaceCount check_faces(const TetMesh& mesh, Violations& violations) {
  FaceCount count;
  std::int64_t overfull = 0, same_side = 0;
  Triangle first_overfull{}, first_same_side{};
  for_each_face(mesh.tets, mesh.points.size(), [&](const FaceSlot* group, std::size_t tets_on_face) {
    ++count.faces;
    auto oriented = [&](std::size_t k) { return outward_face(mesh.tets[group[k].slot / 4], int(group[k].slot % 4)); };
    if (tets_on_face == 1) {
      count.boundary.push_back(oriented(0));
    } else if (tets_on_face == 2) {
      // Two tets on the same side of their shared face overlap.
      if (normalized(oriented(0)) == normalized(oriented(1)) && same_side++ == 0) first_same_side = oriented(0);
    } else if (overfull++ == 0) {
      first_overfull = oriented(0);
    }
  });
  if (overfull > 0)
    violations.push_back(std::to_string(overfull) +
                         " triangles are in more than two tets, first: " + format_triangle(first_overfull));
  if (same_side > 0)
    violations.push_back(
        std::to_string(same_side) +
        " triangles have both their tets on the same side (overlap), first: " + format_triangle(first_same_side));
  return count;
}

// For a 3-manifold with boundary, chi(M) = chi(boundary) / 2.
void check_euler(const TetMesh& mesh, std::int64_t used_count, std::int64_t face_count, const SurfaceMesh& input,
                 CheckReport& report) {
  const std::int64_t edge_count = count_edges(mesh.tets, mesh.points.size());
  report.euler_mesh =
      static_cast<long>(used_count - edge_count + face_count - static_cast<std::int64_t>(mesh.tets.size()));
  const long input_chi = surface_euler_characteristic(input);
  report.euler_expected = input_chi / 2;
  if (2 * report.euler_mesh != input_chi)
    report.violations.push_back("V-E+F-T of the mesh is " + std::to_string(report.euler_mesh) +
                                ", expected half the Euler characteristic of the input, " + std::to_string(input_chi) +
                                "/2");
}

// The mesh vertex with the same exact coordinates as each input vertex used by a triangle
// (-1 for unused or missing ones).
std::vector<std::int32_t> find_input_vertices(const SurfaceMesh& input, const std::vector<KeyedVertex>& by_coordinates,
                                              Violations& violations) {
  std::vector<std::int32_t> mesh_vertex_of(input.points.size(), -1);
  std::vector<char> in_triangle(input.points.size(), 0);
  for (const Triangle& t : input.triangles)
    for (std::int32_t v : t)
      if (v >= 0 && static_cast<std::size_t>(v) < in_triangle.size()) in_triangle[v] = 1;
  std::int64_t missing = 0, first = -1;
  for (std::size_t v = 0; v < input.points.size(); ++v) {
    if (!in_triangle[v]) continue;
    KeyedVertex probe{coordinate_key(input.points[v]), -1};
    auto it = std::lower_bound(by_coordinates.begin(), by_coordinates.end(), probe);
    if (it != by_coordinates.end() && it->key == probe.key) {
      mesh_vertex_of[v] = it->index;
    } else if (missing++ == 0) {
      first = static_cast<std::int64_t>(v);
    }
  }
  if (missing > 0)
    violations.push_back("input vertex " + std::to_string(first) +
                         " is missing from the mesh (coordinates changed?); " + std::to_string(missing) +
                         " input vertices missing in all");
  return mesh_vertex_of;
}

// The input triangles that are not boundary faces (split ones), and a grid over their bounding
// boxes to find the one a boundary face lies in.
class SplitTriangles {
 public:
  SplitTriangles(const SurfaceMesh& input, std::vector<std::int64_t> triangles)
      : input_(input), triangles_(std::move(triangles)), covered_(triangles_.size(), 0) {
    Point3 lo{HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (const Point3& p : input.points)
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
    const double diagonal = std::sqrt(dot(sub(hi, lo), sub(hi, lo)));
    tolerance_ = 1e-9 * diagonal;
    // Cells of about a triangle's size; a few large triangles among small ones span at most 33
    // cells a side.
    double extent = 0, largest = 0;
    for (std::int64_t t : triangles_) extent += box_of(t, 0).extent, largest = std::max(largest, box_of(t, 0).extent);
    cell_ = std::max({extent / std::max<std::size_t>(triangles_.size(), 1), largest / 32, 1e-6 * diagonal + 1e-300});
    for (std::size_t i = 0; i < triangles_.size(); ++i) {
      const Box b = box_of(triangles_[i], tolerance_);
      for (std::int64_t x = cell(b.lo[0]); x <= cell(b.hi[0]); ++x)
        for (std::int64_t y = cell(b.lo[1]); y <= cell(b.hi[1]); ++y)
          for (std::int64_t z = cell(b.lo[2]); z <= cell(b.hi[2]); ++z) grid_[key(x, y, z)].push_back(i);
    }
  }

  // Adds the face (mesh points) to the split triangle it lies in, facing the same way; false if none.
  bool add(const Triangle& face, const std::vector<Point3>& points) {
    const Point3 c = centroid(points[face[0]], points[face[1]], points[face[2]]);
    auto bucket = grid_.find(key(cell(c[0]), cell(c[1]), cell(c[2])));
    if (bucket == grid_.end()) return false;
    for (std::size_t i : bucket->second) {
      const Triangle& t = input_.triangles[triangles_[i]];
      const Point3 &a = input_.points[t[0]], &b = input_.points[t[1]], &d = input_.points[t[2]];
      const Point3 n = cross(sub(b, a), sub(d, a));
      const double n_length = std::sqrt(dot(n, n));
      if (!(n_length > 0)) continue;
      const auto inside = [&](const Point3& p) {
        if (std::abs(dot(sub(p, a), n)) > tolerance_ * n_length) return false;  // off its plane
        for (const auto& [u, v] : {std::pair{a, b}, std::pair{b, d}, std::pair{d, a}})
          if (dot(cross(sub(v, u), sub(p, u)), n) < -tolerance_ * n_length * distance(u, v)) return false;
        return true;
      };
      if (!inside(points[face[0]]) || !inside(points[face[1]]) || !inside(points[face[2]])) continue;
      const Point3 m = cross(sub(points[face[1]], points[face[0]]), sub(points[face[2]], points[face[0]]));
      if (dot(m, n) <= 0) continue;  // facing the other way
      area_[i] += std::sqrt(static_cast<long double>(dot(m, m)));
      covered_[i] = 1;
      return true;
    }
    return false;
  }

  // The first split triangle its parts do not cover (area), or -1.
  std::int64_t first_uncovered() const {
    for (std::size_t i = 0; i < triangles_.size(); ++i) {
      const Triangle& t = input_.triangles[triangles_[i]];
      const Point3& a = input_.points[t[0]];
      const Point3 n = cross(sub(input_.points[t[1]], a), sub(input_.points[t[2]], a));
      const long double area = std::sqrt(static_cast<long double>(dot(n, n)));
      const auto parts = area_.count(i) ? area_.at(i) : 0.0L;
      if (!covered_[i] || std::abs(parts - area) > 1e-9L * area + tolerance_ * tolerance_) return triangles_[i];
    }
    return -1;
  }
  std::size_t size() const { return triangles_.size(); }

 private:
  struct Box {
    Point3 lo, hi;
    double extent;
  };
  Box box_of(std::int64_t t, double grow) const {
    Box b{{HUGE_VAL, HUGE_VAL, HUGE_VAL}, {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, 0};
    for (std::int32_t v : input_.triangles[t])
      for (int k = 0; k < 3; ++k)
        b.lo[k] = std::min(b.lo[k], input_.points[v][k] - grow),
        b.hi[k] = std::max(b.hi[k], input_.points[v][k] + grow);
    b.extent = std::max({b.hi[0] - b.lo[0], b.hi[1] - b.lo[1], b.hi[2] - b.lo[2]});
    return b;
  }
  static Point3 centroid(const Point3& a, const Point3& b, const Point3& c) {
    return {(a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3, (a[2] + b[2] + c[2]) / 3};
  }
  std::int64_t cell(double x) const { return static_cast<std::int64_t>(std::floor(x / cell_)); }
  static std::uint64_t key(std::int64_t x, std::int64_t y, std::int64_t z) {
    return (static_cast<std::uint64_t>(x) * 73856093u) ^ (static_cast<std::uint64_t>(y) * 19349663u) ^
           (static_cast<std::uint64_t>(z) * 83492791u);
  }

  const SurfaceMesh& input_;
  std::vector<std::int64_t> triangles_;
  std::vector<char> covered_;
  std::unordered_map<std::size_t, long double> area_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> grid_;
  double tolerance_ = 0, cell_ = 1;
};

// With split faces allowed: the boundary faces that are not input triangles must tile the input
// triangles that are not boundary faces.
void check_split_faces(const SurfaceMesh& input, const TetMesh& mesh, std::vector<std::int64_t> split,
                       const std::vector<Triangle>& parts, CheckReport& report) {
  SplitTriangles triangles(input, std::move(split));
  std::int64_t stray = 0;
  Triangle first_stray{};
  for (const Triangle& f : parts)
    if (!triangles.add(f, mesh.points) && stray++ == 0) first_stray = f;
  report.split_input_faces = static_cast<std::int64_t>(triangles.size());
  if (stray > 0)
    report.violations.push_back(std::to_string(stray) +
                                " boundary faces of the mesh are neither input triangles nor parts of one (facing the "
                                "same way), first: " +
                                format_triangle(first_stray));
  else if (const std::int64_t t = triangles.first_uncovered(); t >= 0)
    report.violations.push_back("input triangle " + std::to_string(t) +
                                " is neither a boundary face of the mesh nor covered by its parts");
}

// Boundary faces must be exactly the input triangles, with the same orientation (or, with split
// faces allowed, tile the others: check_split_faces).
void check_boundary_is_input(const std::vector<Triangle>& boundary, const SurfaceMesh& input, const TetMesh& mesh,
                             const std::vector<std::int32_t>& mesh_vertex_of, BoundaryRule rule, CheckReport& report) {
  Violations& violations = report.violations;
  std::vector<std::int64_t> missing_triangles;
  std::vector<Triangle> extra_faces;
  std::vector<Triangle> boundary_set(boundary.size());
  std::transform(boundary.begin(), boundary.end(), boundary_set.begin(), normalized);
  std::sort(boundary_set.begin(), boundary_set.end());
  std::vector<Triangle> input_set;
  input_set.reserve(input.triangles.size());
  std::int64_t missing = 0, flipped = 0, extra = 0;
  std::int64_t first_missing = -1, first_flipped = -1;
  Triangle first_extra{};
  auto contains = [](const std::vector<Triangle>& set, const Triangle& t) {
    return std::binary_search(set.begin(), set.end(), t);
  };
  for (std::size_t i = 0; i < input.triangles.size(); ++i) {
    const Triangle& t = input.triangles[i];
    bool mapped = true;
    Triangle m{};
    for (int k = 0; k < 3; ++k) {
      bool valid = t[k] >= 0 && static_cast<std::size_t>(t[k]) < mesh_vertex_of.size();
      m[k] = valid ? mesh_vertex_of[t[k]] : -1;
      mapped = mapped && m[k] >= 0;
    }
    if (mapped) {
      m = normalized(m);
      input_set.push_back(m);
      if (contains(boundary_set, m)) continue;
      if (contains(boundary_set, reversed(m))) {
        if (flipped++ == 0) first_flipped = static_cast<std::int64_t>(i);
        continue;
      }
    }
    if (missing++ == 0) first_missing = static_cast<std::int64_t>(i);
    missing_triangles.push_back(static_cast<std::int64_t>(i));
  }
  std::sort(input_set.begin(), input_set.end());
  for (const Triangle& f : boundary)
    if (!contains(input_set, normalized(f)) && !contains(input_set, reversed(f))) {
      if (extra++ == 0) first_extra = f;
      extra_faces.push_back(f);
    }
  if (rule == BoundaryRule::split_allowed && flipped == 0) {
    check_split_faces(input, mesh, std::move(missing_triangles), extra_faces, report);
    return;
  }
  if (missing > 0)
    violations.push_back(std::to_string(missing) +
                         " input triangles are not boundary faces of the mesh, first: input triangle " +
                         std::to_string(first_missing));
  if (flipped > 0)
    violations.push_back(std::to_string(flipped) +
                         " input triangles are boundary faces with the wrong orientation, first: input triangle " +
                         std::to_string(first_flipped));
  if (extra > 0)
    violations.push_back(std::to_string(extra) +
                         " boundary faces of the mesh are not input triangles, first: " + format_triangle(first_extra));
}

// The tets must fill exactly what the input encloses (catches filled cavities).
void check_volume(const SurfaceMesh& input, long double tet_volume, CheckReport& report) {
  const long double surface_volume = enclosed_volume_precise(input);
  report.surface_volume = static_cast<double>(surface_volume);
  const long double scale = std::max(std::abs(tet_volume), std::abs(surface_volume));
  if (std::abs(tet_volume - surface_volume) > kVolumeTolerance * scale)
    report.violations.push_back("tet volume " + format_number(report.tet_volume) +
                                " differs from the volume enclosed by the input, " +
                                format_number(report.surface_volume));
}

// All files of a set carry the same ID.
void check_set_ids(const TetgenFileSet& files, Violations& violations) {
  if (std::string mixed = set_id_violation(files.ids); !mixed.empty()) violations.push_back(std::move(mixed));
}

// .face holds exactly the boundary faces: outward when partet wrote the set, in any orientation
// otherwise (TetGen's own .face does not promise one).
void check_face_file(const TetgenFileSet& files, Violations& violations) {
  if (!files.has_faces) return;
  const bool oriented = files.faces_outward || (!files.ids.empty() && !files.ids.front().second.empty());
  std::vector<Triangle> boundary;
  for (std::size_t t = 0; t < files.mesh.tets.size(); ++t)
    for (int j = 0; j < 4; ++j)
      if (files.mesh.neighbours[t][j] < 0) boundary.push_back(outward_face(files.mesh.tets[t], j));
  auto key = [&](Triangle f) {
    if (oriented) return normalized(f);
    std::sort(f.begin(), f.end());
    return f;
  };
  std::vector<Triangle> expected, found;
  for (const Triangle& f : boundary) expected.push_back(key(f));
  for (const Triangle& f : files.faces) found.push_back(key(f));
  std::sort(expected.begin(), expected.end());
  std::sort(found.begin(), found.end());
  if (expected == found) return;
  std::vector<Triangle> extra, missing;
  std::set_difference(found.begin(), found.end(), expected.begin(), expected.end(), std::back_inserter(extra));
  std::set_difference(expected.begin(), expected.end(), found.begin(), found.end(), std::back_inserter(missing));
  violations.push_back(files.faces_named + " not list exactly the " + std::string(oriented ? "outward " : "") +
                       "boundary faces: " + std::to_string(extra.size()) + " listed faces are not boundary faces" +
                       (extra.empty() ? "" : " (first " + format_triangle(extra.front()) + ")") + ", " +
                       std::to_string(missing.size()) + " boundary faces are missing" +
                       (missing.empty() ? "" : " (first " + format_triangle(missing.front()) + ")"));
}

// .neigh holds exactly the neighbours the tets imply (symmetric, across shared faces).
void check_neigh_file(const TetgenFileSet& files, Violations& violations) {
  if (!files.has_neighbours) return;
  std::int64_t wrong = 0, first = -1;
  for (std::size_t t = 0; t < files.mesh.tets.size(); ++t)
    if (files.neighbours[t] != files.mesh.neighbours[t] && wrong++ == 0) first = static_cast<std::int64_t>(t);
  if (wrong > 0)
    violations.push_back(std::to_string(wrong) +
                         " rows of the .neigh file differ from the neighbours the tets imply, first: tet " +
                         std::to_string(first));
}

}  // namespace

std::string set_id_violation(const std::vector<std::pair<std::string, std::string>>& ids) {
  for (const auto& [file, id] : ids)
    if (id != ids.front().second)
      return "the files come from different runs: " + ids.front().first + " has mesh ID '" + ids.front().second +
             "', " + file + " has '" + id + "'";
  return "";
}

CheckReport check_mesh_files(const SurfaceMesh& input, const TetgenFileSet& files, BoundaryRule rule) {
  CheckReport report = check_mesh(input, files.mesh, rule);
  check_set_ids(files, report.violations);
  check_face_file(files, report.violations);
  check_neigh_file(files, report.violations);
  return report;
}

CheckReport check_mesh(const SurfaceMesh& input, const TetMesh& mesh, BoundaryRule rule) {
  CheckReport report;
  report.vertices = static_cast<std::int64_t>(mesh.points.size());
  report.tets = static_cast<std::int64_t>(mesh.tets.size());
  if (!check_indices(mesh, report.violations)) return report;
  const long double tet_volume = check_orientation(mesh, report.violations);
  report.tet_volume = static_cast<double>(tet_volume);
  const std::int64_t used_count = check_unused_vertices(mesh, report.violations);
  const std::vector<KeyedVertex> by_coordinates = check_duplicate_vertices(mesh, report.violations);
  const FaceCount faces = check_faces(mesh, report.violations);
  report.boundary_faces = static_cast<std::int64_t>(faces.boundary.size());
  check_euler(mesh, used_count, faces.faces, input, report);
  const auto mesh_vertex_of = find_input_vertices(input, by_coordinates, report.violations);
  check_boundary_is_input(faces.boundary, input, mesh, mesh_vertex_of, rule, report);
  check_volume(input, tet_volume, report);
  report.quality = mesh_quality(mesh);
  return report;
}

}  // namespace partet
