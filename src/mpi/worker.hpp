// A worker rank's side of the meshing (internal header): it meshes the pieces and seam regions
// and triangulates the caps rank 0 hands out, keeps the bulks of the pieces it split, numbers
// and sends them back when rank 0 asks. Rank 0 does the same work on its own pieces through the
// first two functions.
#pragma once
#include <functional>

#include "job/job.hpp"
#include "runner/serialize.hpp"
#include "stages/closure.hpp"
#include "stages/piece.hpp"

namespace partet::mpi {

// Triangulates a cap on this rank, its PartitionError kept as the outcome's failure, and counts
// it in stats. `before` runs first, inside the same handling (a test hook).
CapOutcome triangulated(const CapBorder& border, RankStats& stats, const std::function<void()>& before = {});

// Writes the piece's closed surface as DIR/piece_<i>.off (--dump-pieces DIR), for looking at a
// failing piece.
void dump_piece(const MeshJob& job, const PieceSurface& piece);

// A worker: in each round, mesh the pieces and build the caps rank 0 hands out until it sends an
// empty message; between rounds, send the bulks it kept when rank 0 asks for them.
void worker_loop(const MeshJob& job, int rank, RankStats& stats);

}  // namespace partet::mpi
