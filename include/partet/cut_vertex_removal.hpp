// Cut-vertex removal: take out every vertex partitioning inserted on an input edge, and
// re-tetrahedralize the region around them so every input triangle is a face of the mesh.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "partet/mesh_types.hpp"
#include "partet/partition.hpp"

namespace partet {

struct CutVertexRemovalStats {
  std::int64_t removed = 0;          // cut vertices taken out
  std::int64_t cavity_tets_in = 0;   // tets replaced
  std::int64_t cavity_tets_out = 0;  // tets that replaced them
};

// Tetrahedralizes a closed surface (points, triangles), keeping its boundary; throws
// MeshingError. The pipeline passes PieceRunner::mesh_surface.
using SurfaceMesher = std::function<LocalTetMesh(const std::vector<Point3>&, const std::vector<Triangle>&)>;

// The union of the stars of all cut vertices is re-meshed, one connected part at a time, with
// its boundary fixed, except that the split fragments of input triangles are replaced by the
// input triangles themselves. A part that fails grows by up to three layers of tets first.
// Afterwards the mesh has no cut vertices and no unused points; input vertices keep their
// relative order and coordinates. Throws the MeshingError of the part that failed, with the cut
// planes of that part.
CutVertexRemovalStats remove_cut_vertices(TetMesh& mesh, const SurfaceMesh& input, const SplitSurface& split,
                                          const SurfaceMesher& mesher);

}  // namespace partet
