// Partition: PCA axis, k-1 parallel cut planes in vertex gaps, and the input triangles split
// so that every piece's open border lies on a cut plane.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "partet/mesh_types.hpp"

namespace partet {

// The plane {x : dot(normal, x) == offset}. normal is a unit vector shared by all planes.
struct CutPlane {
  Point3 normal;
  double offset;
};

// Direction of the cut planes' normal. coordinate_near_pca (the default) takes the coordinate
// axis closest to the main PCA axis: every crossing point then lies exactly on its plane and
// the caps are exactly planar. pca takes the PCA axis itself (the paper's choice); crossing
// points are then rounded off the plane by up to half an ulp. x, y and z name a coordinate axis
// (exactly planar caps too).
enum class CutAxis { coordinate_near_pca, pca, x, y, z };

// The coordinate axes (as x, y, z) from the closest to the main PCA axis to the farthest.
std::vector<CutAxis> coordinate_axes_by_closeness(const SurfaceMesh& surface);
// "x", "y", "z", "pca" or "auto".
const char* axis_name(CutAxis axis);

Point3 cut_axis(const SurfaceMesh& surface, CutAxis mode);

// Returns k-1 planes, ordered by offset, perpendicular to the main PCA axis of the used input
// vertices, that split the vertices into k groups of about equal size. Each plane lies in the
// middle of a gap between consecutive projected vertices and is checked with exact predicates
// to pass through no vertex. When the vertices have fewer than k distinct positions along the
// axis, fewer planes are returned (one per usable gap). Throws OptionError if k < 1.
// shifts[j] > 0 moves plane j to its (shifts[j]+1)-th widest nearby gap (used to retry a cut
// that caused trouble). fractions (k-1 increasing values in (0, 1)), when given, replace the
// equal split: plane j goes where a fraction fractions[j] of the vertices lies below it.
std::vector<CutPlane> choose_cut_planes(const SurfaceMesh& surface, int k, CutAxis mode = CutAxis::coordinate_near_pca,
                                        const std::vector<int>& shifts = {}, const std::vector<double>& fractions = {});

// The used vertices in order along an axis: what balancing the pieces and choosing the planes
// both read, so one sort of the millions of vertices serves both.
struct AxisVertices {
  // Not an aggregate: a braced axis {1, 0, 0} must not read as one.
  explicit AxisVertices(const Point3& along_axis) : axis(along_axis) {}
  Point3 axis;
  std::vector<std::pair<double, std::size_t>> sorted;  // (projection, vertex), by projection then vertex
};
AxisVertices sort_vertices_along(const SurfaceMesh& surface, const Point3& axis);
// choose_cut_planes along `along.axis`.
std::vector<CutPlane> choose_cut_planes(const SurfaceMesh& surface, const AxisVertices& along, int k,
                                        const std::vector<int>& shifts = {}, const std::vector<double>& fractions = {});

// Piece (slab) of a point: the number of planes it lies above, decided exactly.
// Only valid for points on no plane.
int piece_of_point(const std::vector<CutPlane>& planes, const Point3& p);

// The input surface with every triangle that crosses a plane split at the crossings.
struct SplitSurface {
  std::vector<Point3> points;  // input vertices, then cut vertices
  std::int32_t input_vertex_count = 0;
  std::vector<Triangle> triangles;                           // oriented like the input
  std::vector<std::int32_t> piece;                           // piece of each triangle (0..k-1)
  std::vector<std::int32_t> parent;                          // input triangle each triangle comes from
  std::vector<std::array<std::int32_t, 2>> cut_vertex_edge;  // input edge a cut vertex splits
  std::vector<std::int32_t> cut_vertex_plane;                // plane a cut vertex lies on
  // The caps' interior points follow the cut vertices in `points`; the plane of each.
  std::vector<std::int32_t> cap_point_plane;
  int piece_count = 1;

  bool is_cut_vertex(std::int32_t v) const { return v >= input_vertex_count; }
  std::int32_t cut_vertex_count() const { return static_cast<std::int32_t>(cut_vertex_plane.size()); }
  // One past the last plane with a cut vertex or cap point (planes past it have nothing to heal).
  int plane_count() const {
    int planes = 0;
    for (auto p : cut_vertex_plane) planes = std::max(planes, p + 1);
    for (auto p : cap_point_plane) planes = std::max(planes, p + 1);
    return planes;
  }
};

// Splits the triangles at the planes. Each crossing of an input edge with a plane is
// constructed once in exact arithmetic and rounded to double once.
SplitSurface split_at_planes(const SurfaceMesh& surface, const std::vector<CutPlane>& planes);

// Keeps of the split triangles only those with a cut vertex, with their parents: all that seam
// healing reads of them once the pieces are built. The piece labels go (shrunk to fit: rank 0
// holds this beside the whole merged mesh).
void keep_seam_triangles(SplitSurface& split);

}  // namespace partet
