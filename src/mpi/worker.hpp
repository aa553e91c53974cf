// A worker rank's side of the meshing (internal header): it meshes the pieces and seam regions
// and triangulates the caps rank 0 hands out, keeps the bulks of the pieces it split, numbers
// and sends them back when rank 0 asks. Rank 0 does the same work on its own pieces through the
// first two functions.
#pragma once
#include <functional>
#include <map>
#include <memory>

#include "job/job.hpp"
#include "runner/serialize.hpp"
#include "stages/closure.hpp"
#include "stages/piece.hpp"
#include "stages/seam_band.hpp"
#include "stages/seam_chain_band.hpp"

namespace partet::mpi {

// Triangulates a cap on this rank, its PartitionError kept as the outcome's failure, and counts
// it in stats. `before` runs first, inside the same handling (a test hook).
CapOutcome triangulated(const CapBorder& border, RankStats& stats, const std::function<void()>& before = {});

// Writes the piece's closed surface as DIR/piece_<i>.off (--dump-pieces DIR), for looking at a
// failing piece.
void dump_piece(const MeshJob& job, const PieceSurface& piece);

class KeptBulks;

// A worker rank. The bulks it keeps live as long as it does, so that when rank 0 leaves the mesh
// spread (spread_mesh.hpp), this rank writes them itself.
class Worker {
 public:
  Worker(const MeshJob& job, int rank, RankStats& stats);
  ~Worker();
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;
  // In each round, mesh the pieces and build the caps rank 0 hands out until it sends an empty
  // message; between rounds, number, link and send the bulks it kept when rank 0 asks. Returns
  // when rank 0 says the meshing is done.
  void mesh_rounds();
  // The bulks it still keeps, by piece, numbered as in the output (it keeps none afterwards).
  std::map<int, TetBlock> take_kept_bulks();
  // The seam chains it healed and kept (HealOptions::keep_healed), by the index rank 0 gave them.
  std::map<int, HealedChain> take_kept_chains();

 private:
  const MeshJob& job_;
  int rank_;
  RankStats& stats_;
  std::unique_ptr<KeptBulks> kept_;
};

// A worker for one job: Worker(...).mesh_rounds().
void worker_loop(const MeshJob& job, int rank, RankStats& stats);

}  // namespace partet::mpi
