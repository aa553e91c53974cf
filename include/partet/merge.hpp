// Merge: weld the pieces' tet meshes at the caps into one mesh with global numbering.
#pragma once
#include <vector>

#include "partet/mesh_types.hpp"
#include "partet/piece.hpp"

namespace partet {

// surface_points are the global points (input, cut and cap points); each piece's Steiner
// points are appended in piece order. Cap vertices are welded by id, never by coordinates;
// neighbours across caps are restored by matching faces. Pieces must be ordered by index.
// Each piece's arrays are freed as soon as they are welded.
TetMesh weld(const std::vector<Point3>& surface_points, const std::vector<PieceSurface>& pieces,
             std::vector<PieceTetMesh>&& results);

}  // namespace partet
