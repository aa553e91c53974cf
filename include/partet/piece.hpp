// A piece: the closed surface of one slab (its part of the input plus its caps), numbered
// locally, with the global id of every local point.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "partet/closure.hpp"
#include "partet/errors.hpp"
#include "partet/mesh_types.hpp"
#include "partet/partition.hpp"

namespace partet {

struct PieceSurface {
  int index = 0;
  std::vector<std::int32_t> global_ids;  // local point -> global point, ascending
  std::vector<Point3> points;
  std::vector<Triangle> triangles;  // local ids, outward
};

// What meshing one piece gave: its result, or why it failed.
struct PieceOutcome {
  PieceTetMesh result;
  std::optional<Failure> failure;
};

std::vector<PieceSurface> assemble_pieces(const SplitSurface& split, const std::vector<Cap>& caps);

// Cheap combinatorial checks of a piece (closed, manifold, oriented). Throws MeshingError
// (bad_surface) naming the piece.
void check_piece_topology(const PieceSurface& piece);

}  // namespace partet
