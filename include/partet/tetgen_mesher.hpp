// The only user of TetGen: tetrahedralizes a closed surface in this process without touching
// its boundary. Where the work runs (this process or an isolated child) is piece_runner's job.
#pragma once
#include <string>
#include <vector>

#include "partet/mesh_types.hpp"
#include "partet/piece.hpp"

namespace partet {

struct TetgenOptions {
  std::string quality;  // "" = none; "R" or "R/ANGLE": TetGen's -q (radius-edge ratio / min dihedral)
};

// Meshes the solid bounded by `triangles` (TetGen -pY, plus -q when asked). Regions the surface
// encloses with winding number 0 (cavities) get no tets. Verifies that the boundary of the
// result is exactly the input triangles. Throws MeshingError naming `piece` on any failure.
// Not thread safe: TetGen keeps global state.
LocalTetMesh mesh_closed_surface(const std::vector<Point3>& points, const std::vector<Triangle>& triangles,
                                 const TetgenOptions& options, int piece = -1);

// Checks the piece (closed, manifold, no self-intersections) and meshes it.
PieceTetMesh tetrahedralize_piece(const PieceSurface& piece, const TetgenOptions& options);

}  // namespace partet
