// A piece: the closed surface of one slab (its part of the input plus its caps), numbered
// locally, with the global id of every local point.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "stages/closure.hpp"
#include "partet/errors.hpp"
#include "partet/mesh_types.hpp"
#include "stages/partition.hpp"
#include "stages/seam_band.hpp"

namespace partet {

struct PieceSurface {
  int index = 0;
  // A region around a seam being re-meshed rather than a piece: its boundary (faces of the tets
  // around it) may pinch at vertices and enclose pockets, so every region TetGen fills is
  // classified, and the piece topology check does not apply.
  bool seam_region = false;
  std::vector<std::int32_t> global_ids;  // local point -> global point, ascending
  std::vector<Point3> points;
  std::vector<Triangle> triangles;  // local ids, outward
};

// What meshing one piece gave: its result, or why it failed.
struct PieceOutcome {
  PieceTetMesh result;
  std::optional<Failure> failure;
  double seconds = 0;    // wall time of the meshing, where it ran
  double memory_mb = 0;  // peak memory the meshing added to the process it ran in (a child: its own)
  // Instead of the result, split where it was meshed (split_where_meshed): its band, the bulk
  // kept there.
  std::optional<PieceBand> band{};
};

// Builds the pieces one at a time, each as soon as the caps on both its sides exist. Each
// piece's part of the input is handed over once (assemble moves it out).
class PieceAssembler {
 public:
  explicit PieceAssembler(const SplitSurface& split);
  // below: the cap of plane p-1 (none for the first piece); above: of plane p (none for the last).
  PieceSurface assemble(int p, const Cap* below, const Cap* above);

 private:
  const SplitSurface& split_;
  std::vector<std::vector<Triangle>> input_part_;  // split triangles by piece
  std::vector<std::int32_t> scratch_;
};


// Cheap combinatorial checks of a piece (closed, manifold, oriented). Throws MeshingError
// (bad_surface) naming the piece.
void check_piece_topology(const PieceSurface& piece);

}  // namespace partet
