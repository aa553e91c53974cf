// Cut-vertex removal: take out every vertex partitioning inserted on an input edge, and
// re-tetrahedralize the region around them so every input triangle is a face of the mesh.
#pragma once
#include <string>
#include <vector>

#include "partet/errors.hpp"
#include "partet/mesh_types.hpp"
#include "partet/partition.hpp"
#include "partet/tetgen_mesher.hpp"

namespace partet {

// Re-meshing the region around some cut vertices failed; planes lists the cut planes those
// vertices lie on (moving them is the remedy).
struct CutRemovalError : MeshingError {
  CutRemovalError(const std::string& what, std::vector<int> planes_involved)
      : MeshingError(-1, what), planes(std::move(planes_involved)) {}
  std::vector<int> planes;
};

struct CutVertexRemovalStats {
  std::int64_t removed = 0;          // cut vertices taken out
  std::int64_t cavity_tets_in = 0;   // tets replaced
  std::int64_t cavity_tets_out = 0;  // tets that replaced them
};

// The union of the stars of all cut vertices is re-meshed by TetGen (-pY), one connected part
// at a time (a part that fails grows by up to three layers of tets first), with its boundary fixed, except that the split fragments of input triangles are replaced by the input triangles
// themselves. Afterwards the mesh has no cut vertices and no unused points; input vertices keep
// their relative order and coordinates. Throws CutRemovalError on failure.
CutVertexRemovalStats remove_cut_vertices(TetMesh& mesh, const SurfaceMesh& input, const SplitSurface& split,
                                          const TetgenOptions& options);

}  // namespace partet
