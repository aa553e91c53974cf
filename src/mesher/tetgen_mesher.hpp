// The only user of TetGen: tetrahedralizes a closed surface in this process without touching
// its boundary. Where the work runs (this process or an isolated child) is piece_runner's job.
#pragma once
#include <string>
#include <vector>

#include "partet/mesh_types.hpp"
#include "stages/piece.hpp"

namespace partet {

struct TetgenOptions {
  std::string quality;  // "" = none; "R" or "R/ANGLE": TetGen's -q (radius-edge ratio / min dihedral)
  // "" = TetGen's default; else TetGen's -T (the tolerance of its coplanarity test). A retry uses
  // a tiny one when TetGen calls a valid input self-intersecting (very thin solids).
  std::string tolerance;
  // "" = TetGen's default (level 2, every scheme); else TetGen's -O value "LEVEL/SCHEMES". The
  // polish uses the most thorough one, "9/7", on small neighbourhoods only.
  std::string optimization;
  // TetGen may put points on the surface, splitting input triangles (its -p without -Y). Only for
  // an input TetGen cannot mesh otherwise, when the user allows it (--allow-split-faces): the
  // pieces' caps must stay whole, so this meshes the input as one piece.
  bool boundary_points = false;
};

// Checks a quality bound before it reaches TetGen: "R" or "R/ANGLE", plain decimal numbers with
// 1 <= R <= 100 and 0 <= ANGLE <= 20 (TetGen does not finish with tighter bounds). Returns it
// in TetGen's form; throws OptionError.
std::string parse_quality(const std::string& text);

// The message of a MeshingError when TetGen itself ran out of memory (its error code 1).
inline constexpr const char* kTetgenOutOfMemory = "TetGen ran out of memory";

// What the caller knows about the regions a surface encloses.
enum class SurfaceRegions {
  any,        // cavities, pockets: classify every region TetGen fills by orientation
  one_shell,  // one manifold shell: everything TetGen keeps is solid
};

// Meshes the solid bounded by `triangles` (TetGen -pY, plus -q when asked). Regions the surface
// encloses with winding number 0 (cavities) get no tets. Verifies that the boundary of the
// result is exactly the input triangles (with options.boundary_points: that every boundary face
// lies in an input triangle, facing the same way, and every input triangle holds one; the points
// TetGen added on the surface are among the Steiner points). Throws MeshingError naming `piece`
// on any failure.
// Not thread safe: TetGen keeps global state.
LocalTetMesh mesh_closed_surface(const std::vector<Point3>& points, const std::vector<Triangle>& triangles,
                                 const TetgenOptions& options, int piece = -1,
                                 SurfaceRegions regions = SurfaceRegions::any);

// Checks the piece's topology (closed, manifold, oriented) and meshes it. Self-intersections
// make TetGen fail (or the result's boundary differ from the piece), never pass silently.
PieceTetMesh tetrahedralize_piece(const PieceSurface& piece, const TetgenOptions& options);

}  // namespace partet
