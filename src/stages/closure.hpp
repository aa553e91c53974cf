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

// Builds the caps one plane at a time (so the pieces on both sides of a plane can be meshed as
// soon as its cap exists). Border chords come from split's triangles; interior points added by
// the refinement are appended to split.points (so they get global ids): build the caps in plane
// order for the same numbering every time. density scales the cap interior resolution: target
// edge length = mean border edge length / density; 0 adds no interior points. Throws
// OptionError for a bad density, PartitionError when the loops on a plane cross or touch.
class CapBuilder {
 public:
  CapBuilder(SplitSurface& split, const std::vector<CutPlane>& planes, double density);
  Cap build(int plane);

 private:
  SplitSurface& split_;
  const std::vector<CutPlane>& planes_;
  double density_;
  std::vector<std::vector<std::array<std::int32_t, 2>>> chords_;  // per plane, as the piece below runs them
};


}  // namespace partet
