// Triangulating a surface file's polygons (internal header).
#pragma once
#include <cstddef>
#include <vector>

#include "partet/mesh_types.hpp"

namespace partet {

// Triangulates a polygon (corner indices into points) with more than three corners, keeping its
// orientation. Convex polygons get a fan; others are ear-clipped in the plane of their dominant
// normal component. Appends to triangles; returns false if no valid triangulation was found.
bool triangulate_polygon(const std::vector<std::size_t>& polygon, const std::vector<Point3>& points,
                         std::vector<Triangle>& triangles);

}  // namespace partet
