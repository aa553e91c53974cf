// `partet info`: what a file holds. For a surface: counts, bounds, shells and genus, and whether
// it is closed, manifold, consistently oriented, outward and free of self-intersections (what
// `partet mesh` needs). For a tet mesh: counts, bounds, volume, solids and quality.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "partet/mesh_types.hpp"
#include "stages/quality.hpp"

namespace partet {

struct Bounds {
  Point3 min{0, 0, 0}, max{0, 0, 0};
};

// Axis-aligned bounds of the points (of those with used[i], when given); all zero when none.
Bounds bounds_of(const std::vector<Point3>& points, const std::vector<char>* used = nullptr);

struct SurfaceInfo {
  std::int64_t vertices = 0, unused_vertices = 0, faces = 0, edges = 0;
  Bounds bounds;
  std::int64_t border_edges = 0;        // in one face: the surface is open there
  std::int64_t non_manifold_edges = 0;  // in three or more faces
  std::int64_t misoriented_edges = 0;   // two faces run through it the same way
  std::int64_t shells = 0;              // connected components (by shared vertices)
  std::int64_t euler = 0;               // V - E + F of the used vertices
  std::int64_t genus = -1;              // total over the shells; -1 unless closed, manifold, oriented
  bool closed() const { return border_edges == 0; }
  bool manifold() const { return non_manifold_edges == 0; }
  bool oriented() const { return misoriented_edges == 0; }
  long double volume = 0;            // enclosed (meaningful when closed and oriented)
  std::string self_intersection;     // empty: none found; else the first pair, as check reports it
  bool self_intersection_checked = false;
  bool meshable() const {
    return closed() && manifold() && oriented() && volume > 0 && self_intersection_checked && self_intersection.empty();
  }
};

// Self-intersections are looked for only in closed, manifold, oriented surfaces (the test needs
// a surface, and costs about as much as reading it).
SurfaceInfo surface_info(const SurfaceMesh& surface);

struct TetMeshInfo {
  std::int64_t vertices = 0, tets = 0, boundary_faces = 0, solids = 0;
  Bounds bounds;
  long double volume = 0;  // sum of the tets' signed volumes
  std::int64_t inverted_tets = 0;
  MeshQuality quality;
};

TetMeshInfo tet_mesh_info(const TetMesh& mesh);

}  // namespace partet
