// The only user of TetGen: tetrahedralizes a closed surface without touching its boundary.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "partet/isolated_run.hpp"
#include "partet/mesh_types.hpp"
#include "partet/piece.hpp"

namespace partet {

struct TetgenOptions {
  std::string quality;  // "" = none; "R" or "R/ANGLE": TetGen's -q (radius-edge ratio / min dihedral)
  // Run TetGen in a forked child process: Debian's TetGen can abort() (failed assert) or loop
  // forever on hard inputs; in a child that becomes an ordinary MeshingError.
  bool isolate = true;
  // Seconds before a TetGen run is given up (isolated runs only); 0 = a limit scaled with the
  // input size (5 s + 1 ms per triangle, x10 with quality refinement).
  double timeout_seconds = 0;
};

// A tet mesh of a closed surface. Points [0, surface point count) are the surface's points in
// the same order; later points are interior Steiner points TetGen added.
struct LocalTetMesh {
  std::vector<Point3> steiner_points;
  std::vector<Tet> tets;        // positively oriented
  std::vector<Tet> neighbours;  // -1 where the face is on the surface
};

// Meshes the solid bounded by `triangles` (TetGen -pY, plus -q when asked). Regions the surface
// encloses with winding number 0 (cavities) get no tets. Verifies that the boundary of the
// result is exactly the input triangles. Throws MeshingError(piece, ...) on any failure.
// Not thread safe: TetGen keeps global state.
LocalTetMesh mesh_closed_surface(const std::vector<Point3>& points, const std::vector<Triangle>& triangles,
                                 const TetgenOptions& options, int piece = -1);

// The time limit used when TetgenOptions::timeout_seconds is 0.
double default_tetgen_timeout(std::size_t triangles, const TetgenOptions& options);

// Drops a leading "piece N: " (the caller's MeshingError adds it again) and names process_name
// in messages about how an isolated process ended.
std::string strip_piece_prefix(const std::string& message, int piece, const std::string& process_name);

// A piece's tet mesh as sent back to rank 0.
struct PieceTetMesh {
  int index = 0;
  std::int32_t surface_point_count = 0;  // local ids below this map through the piece's global_ids
  LocalTetMesh mesh;
};

// Checks the piece (closed, manifold, no self-intersections) and meshes it. With
// options.isolate the checks and TetGen run together in one child process.
PieceTetMesh tetrahedralize_piece(const PieceSurface& piece, const TetgenOptions& options);

// The same, returning the result already serialized (serialize_result), as MPI sends it: the
// bytes come straight from the child process, so no second copy of the mesh is built.
std::string tetrahedralize_piece_to_bytes(const PieceSurface& piece, const TetgenOptions& options);

// Asynchronous form (for a rank that polls MPI meanwhile): starts the checks and TetGen for a
// piece in a child process (before() runs first, in the child); piece_meshing_result waits for
// the serialized result or throws MeshingError naming the piece. The piece must outlive the run.
std::unique_ptr<IsolatedRun> start_piece_meshing(const PieceSurface& piece, const TetgenOptions& options,
                                                 const std::function<void()>& before = {});
std::string piece_meshing_result(IsolatedRun& run, int piece);

}  // namespace partet
