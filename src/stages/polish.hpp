// Quality polish: the worst tets of a refined mesh (slivers, needles) are a lottery of TetGen's
// insertion order, in one run as in the pieces. The polish re-meshes the neighbourhood of each
// poor tet with its boundary fixed, trying larger neighbourhoods and TetGen's stronger
// optimization in turn, and keeps a neighbourhood's new tets only where its worst tet got better.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "partet/mesh_types.hpp"
#include "stages/piece.hpp"

namespace partet {

struct PolishOptions {
  double min_dihedral_deg = 5;  // a tet with a smaller dihedral angle is poor (TetGen's first histogram bin)
  double max_amips = 30;        // so is one with a larger AMIPS energy (3 = regular; a refined mesh averages ~4.3)
  int attempts = 3;             // attempt a re-meshes a + 1 layers of tets around each poor tet
  // A neighbourhood with more tets, or more poor tets, is left as it is: its poor tets are the
  // input's shape (thin walls, slivers between input faces), not a lottery of insertion order,
  // and re-meshing it costs much for nothing (adis16480: 17 s per attempt with -O9/7 for 13k
  // tets holding 7k poor ones, 90% of the run; skull: 232k tets at once). Over 43 models at 4
  // and 8 pieces no neighbourhood above 22,776 tets or 2,436 poor tets was ever kept.
  std::int64_t largest_neighbourhood = 25000;
  std::int64_t most_poor_tets = 5000;
};

struct PolishStats {
  std::int64_t poor_before = 0, poor_after = 0;            // tets below the bounds before and after
  std::int64_t regions = 0;                                // neighbourhoods re-meshed, over all attempts
  std::int64_t improved = 0;                               // of those, kept because their worst tet got better
  std::int64_t left = 0;                                   // neighbourhoods too large or too poor to re-mesh
  std::int64_t tets_in = 0, tets_out = 0;                  // tets replaced, and the tets that replaced them
  double min_dihedral_before = 0, min_dihedral_after = 0;  // the mesh's worst, degrees
  double amips_max_before = 0, amips_max_after = 0;
  // TetGen's refinement ran away in a neighbourhood (the quality bound cannot be met there): the
  // polish stopped, since every other neighbourhood has the same bound.
  bool ran_away = false;
};

// Meshes a batch of closed surfaces (neighbourhoods, as regions) with TetGen's optimization
// `optimization` ("" = TetGen's default, else its -O value such as "9/7"); one outcome per
// surface, in order.
using PolishMesher =
    std::function<std::vector<PieceOutcome>(const std::vector<PieceSurface>& regions, const std::string& optimization)>;

// Re-meshes the neighbourhoods of the poor tets; a neighbourhood whose re-meshing fails or is not
// better keeps its tets. The boundary of the mesh is untouched; unused points are dropped
// (keeping order) and new tets get piece -1. Deterministic for a given mesh and mesher.
PolishStats polish_poor_tets(TetMesh& mesh, const PolishOptions& options, const PolishMesher& mesher);

}  // namespace partet
