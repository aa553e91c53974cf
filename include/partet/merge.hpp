// Merge: weld the pieces' tet meshes at the caps into one mesh with global numbering.
#pragma once
#include <vector>

#include "partet/mesh_types.hpp"
#include "partet/piece.hpp"
#include "partet/tetgen_mesher.hpp"

namespace partet {

// surface_points are the global points (input, cut and cap points); each piece's Steiner
// points are appended in piece order. Cap vertices are welded by id, never by coordinates;
// neighbours across caps are restored by matching faces. Pieces must be ordered by index.
TetMesh weld(const std::vector<Point3>& surface_points, const std::vector<PieceSurface>& pieces,
             const std::vector<PieceTetMesh>& results);
// The same, freeing each piece's arrays once they are welded.
TetMesh weld(const std::vector<Point3>& surface_points, const std::vector<PieceSurface>& pieces,
             std::vector<PieceTetMesh>&& results);

// Recomputes all neighbour relations from the tets (faces matched by vertex ids). Throws
// MeshingError when a face is shared by more than two tets.
std::vector<Tet> compute_neighbours(const std::vector<Tet>& tets);

}  // namespace partet
