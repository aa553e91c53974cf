// Seam chains (internal header): the cuts whose seams heal together. Healing re-meshes the tets
// around the vertices it removes; the seams of two cuts interact only where those neighbourhoods
// meet (a thin piece between them). A chain is a set of groups of cuts (seam_healing.cpp's
// groups: cuts splitting one input triangle) whose bands, the tets within `reach` layers of their
// removed vertices, are joined through faces. Chains plan their rounds apart (seam_rounds.hpp),
// so a chain heals the same whether the other chains heal beside it or not: what lets a chain's
// seam be healed on its own, by the ranks that hold it.
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

#include "partet/mesh_types.hpp"
#include "stages/seam_band.hpp"
#include "stages/topology.hpp"

namespace partet {

struct SeamChains {
  std::vector<int> of_group;  // chain of each group, numbered in the order of their lowest group;
                              // -1 for a group with no vertex left
  int count = 0;
  // Found from the band parts' links: by piece, the chain of each of its parts (-1: none).
  std::vector<std::vector<int>> of_part;
};

// The chains of the groups of the vertices [first, first + group.size()) still to remove
// (group[v - first] >= 0). `reach` is the band's depth in layers of tets across faces
// (seam_band_spec's layers): the band path sees exactly these tets, so the chains found on the
// band are those found on the whole mesh. `groups` is the number of groups.
SeamChains seam_chains(const TetMesh& mesh, std::int32_t first, const std::vector<int>& group, int groups, int reach);

// The links of a piece's band part (its tets in global ids, neighbours within the part); the
// vertices to remove are spec's [first_removed, end_removed). Made where the part is split or
// grown (split_alone, grow_band: on the rank that keeps its bulk), as they name no Steiner point.
BandPartLinks band_part_links(const TetBlock& band, const BandSpec& spec);
// The part of each tet of a piece's band part, as band_part_links numbers them (in the order of
// their first tet).
std::vector<std::int32_t> band_part_labels(const TetBlock& band);

// The chains of every piece's band part (by piece), as seam_chains finds them on the welded band
// of depth `reach` = spec.layers: the groups as there, and the chain of each part (of_part).
// Each part lies in one chain: a chain is whole where its tets are joined through faces.
SeamChains seam_chains(const std::vector<BandPartLinks>& pieces, std::int32_t first, const std::vector<int>& group,
                       int groups);

}  // namespace partet
