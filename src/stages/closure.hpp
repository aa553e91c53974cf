// Surface closure: one planar cap per cut plane, triangulating the region the solid covers on
// that plane, so each piece becomes a closed surface.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "partet/mesh_types.hpp"
#include "stages/partition.hpp"

namespace partet {

// Triangles use global point ids. They are oriented for the piece below the plane (normal
// along +axis); the piece above uses them reversed.
struct Cap {
  int plane = 0;
  std::vector<Triangle> triangles;
  std::int32_t interior_point_count = 0;  // points the refinement added
};

// All one cap's triangulation needs: the border chords on its plane with their points, numbered
// locally, so that any rank can build it (a few kilobytes, against the whole split surface).
struct CapBorder {
  int plane = 0;
  CutPlane cut{};
  double density = 0;
  std::vector<std::int32_t> global_ids;                  // local border point -> global id, ascending
  std::vector<Point3> points;                            // by local id
  std::vector<std::array<std::int32_t, 2>> chords;       // local ids, as the piece below runs them
};

// A cap's triangulation in its border's numbering: ids below the border's point count are border
// points, the next ones interior_points in order.
struct CapShape {
  int plane = 0;
  std::vector<Point3> interior_points;
  std::vector<Triangle> triangles;  // oriented for the piece below the plane
};

// Triangulates the region the solid covers on the plane: a 2D constrained Delaunay triangulation
// of the border loops, its outside removed, its interior filled by a graded lattice of points
// (target edge length next to the border = mean border edge length / density; 0 adds none). The
// same border gives the same shape on every rank. Throws PartitionError when the loops on the
// plane cross or touch.
CapShape triangulate_cap(const CapBorder& border);

// The caps, one plane at a time (so the pieces on both sides of a plane can be meshed as soon as
// its cap exists). Border chords come from split's triangles; place() appends a cap's interior
// points to split.points (so they get global ids): place the caps in plane order for the same
// numbering every time. Throws OptionError for a bad density.
class CapBuilder {
 public:
  CapBuilder(SplitSurface& split, const std::vector<CutPlane>& planes, double density);
  CapBorder border(int plane) const;
  // Gives a shape built from border(plane) global ids. Throws InternalError when it does not fit.
  Cap place(int plane, CapShape&& shape);
  Cap build(int plane) { return place(plane, triangulate_cap(border(plane))); }

 private:
  std::vector<std::int32_t> border_ids(int plane) const;  // ascending

  SplitSurface& split_;
  const std::vector<CutPlane>& planes_;
  double density_;
  std::vector<std::vector<std::array<std::int32_t, 2>>> chords_;  // per plane, global ids
};


}  // namespace partet
