// Re-meshing a region of a tet mesh with its boundary fixed (internal header), shared by seam
// healing and the quality polish: grow the region by layers, hand each part's closed boundary
// to TetGen as a surface, splice the new tets in, drop the points no tet uses any more.
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

#include "partet/mesh_types.hpp"
#include "stages/piece.hpp"

namespace partet {

// Adds to the region every tet sharing a vertex with a tet t for which from(t) holds.
template <class From>
void add_layer(const TetMesh& mesh, From from, std::vector<char>& in_region) {
  std::vector<char> touched(mesh.points.size(), 0);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    if (from(t))
      for (auto v : mesh.tets[t]) touched[v] = 1;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    for (auto v : mesh.tets[t])
      if (touched[v]) in_region[t] = 1;
}

// The tets marked in `mask`, ascending.
std::vector<std::int32_t> marked_tets(const std::vector<char>& mask);

// One part of a region once re-meshed: its new tets in local numbering, and the global id of
// each of its local surface points.
struct RegionMesh {
  std::vector<std::int32_t> ids;
  LocalTetMesh mesh;
};

// The closed surface of one part of a region, for TetGen: `faces` (global ids, outward) are
// numbered locally and `ids` receives the global id of each local point. The surface is marked
// as a region: it may pinch at vertices, so TetGen's regions are classified and the piece
// topology check is skipped.
PieceSurface region_surface(std::vector<Triangle> faces, const TetMesh& mesh, int index, std::vector<std::int32_t>& ids);

// Where replace_region put the tets: the slot of each new tet (in the parts' order), and the
// kept tets it moved into slots left over (from, to, in that order), so per-tet data can follow.
struct Replacement {
  std::vector<std::int32_t> new_tets;
  std::vector<std::pair<std::int32_t, std::int32_t>> moved;
};

// Replaces the region's tets by the parts' new tets (their Steiner points appended), in place:
// the new tets take the region's slots, then new slots at the end; slots left over take the last
// tets. Tets outside the region keep their neighbours among themselves; faces towards the region
// are joined to the new tets. New tets get piece -1. In place because copying the mesh each round
// cost 0.04 s per round on armadillo_loop1 (1.2M tets), a third of a round's other bookkeeping.
// Each part's mesh is freed once its tets are taken.
Replacement replace_region(TetMesh& mesh, const std::vector<char>& in_region, std::vector<RegionMesh> parts);

// Drops the points no tet uses, keeping the order of the others. Returns which old points were
// used.
std::vector<char> drop_unused_points(TetMesh& mesh);

}  // namespace partet
