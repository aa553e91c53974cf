// Seam healing in rounds (internal header): which of the vertices left to remove are re-meshed
// in the next round. Vertices sharing a tet must be re-meshed by one TetGen run, and the parts
// of a round run in parallel, so a round should hold many parts and no needlessly large one.
#pragma once
#include <cstdint>
#include <vector>

#include "partet/mesh_types.hpp"
#include "stages/topology.hpp"

namespace partet {

// The vertices of a tet still to be removed (up to four), and their groups: group_of[v - first]
// as plan_seam_round takes it.
struct TetRemoved {
  std::int32_t vertex[4] = {};
  int group[4] = {};
  int count = 0;
  TetRemoved(const Tet& t, std::int32_t first, const std::vector<int>& group_of) {
    for (auto v : t) {
      const std::int64_t i = static_cast<std::int64_t>(v) - first;
      if (i >= 0 && i < static_cast<std::int64_t>(group_of.size()) && group_of[i] >= 0)
        vertex[count] = v, group[count++] = group_of[i];
    }
  }
};

struct SeamRound {
  std::vector<char> heals;              // by vertex v - first: re-meshed in this round
  std::vector<std::int32_t> star_tets;  // the tets with a vertex left to remove, ascending
};

// Plans the next round on the mesh as it is now. group[v - first] is the group of cuts whose
// vertex v is still to be removed (cuts that split one input triangle between them form one
// group), or -1. Vertices sharing tets form components. A component whose vertices all belong to
// one group heals now. So does a component of several groups (the stars of neighbouring cuts
// meet across a thin piece) that is no larger, in star tets, than the largest set of one group's
// vertices sharing tets in its chain (seam_chains.hpp; all groups are one chain when
// `chain_of_group` is null), so that a chain's plan does not depend on the other chains; otherwise its groups take turns, the one with the most star tets first
// together with every group that meets none taken before it. Planning each round anew matters:
// re-meshing a region can bring the stars left for later rounds together (without a quality
// bound the new tets span the region), and a plan made up front would then re-mesh them as one
// ever larger part (bob.off refined to 2.74M faces, 16 pieces, healed without a quality bound:
// one part of 2M triangles, 64 s in one TetGen run).
// `candidates` (ascending), when given, are the only tets that may hold a vertex left to remove
// (the previous round's star tets that survived it, and its new tets): later rounds then cost
// what their stars cost, not a scan of the whole mesh.
SeamRound plan_seam_round(const TetMesh& mesh, std::int32_t first, const std::vector<int>& group,
                          const std::vector<std::int32_t>* candidates = nullptr,
                          const std::vector<int>* chain_of_group = nullptr);

}  // namespace partet
