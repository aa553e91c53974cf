// Surface closure: one planar cap per cut plane, triangulating the region the solid covers on
// that plane, so each piece becomes a closed surface.
#pragma once
#include <cstdint>
#include <vector>

#include "partet/mesh_types.hpp"
#include "partet/partition.hpp"

namespace partet {

// Triangles use global point ids. They are oriented for the piece below the plane (normal
// along +axis); the piece above uses them reversed.
struct Cap {
  int plane = 0;
  std::vector<Triangle> triangles;
  std::int32_t interior_point_count = 0;  // points the refinement added
};

// Builds the caps. Border chords come from split's triangles; interior points added by the
// refinement are appended to split.points (so they get global ids). density scales the cap
// interior resolution: target edge length = mean border edge length / density; 0 adds no
// interior points. Throws PartitionError when the loops on a plane cross or touch.
std::vector<Cap> build_caps(SplitSurface& split, const std::vector<CutPlane>& planes, double density);

}  // namespace partet
