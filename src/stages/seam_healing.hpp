// Seam healing: after the merge, the vertices the cuts added are taken out again and the region
// around each cut is re-tetrahedralized, so every input triangle is a face of the mesh and, with
// the caps' interior points removed too, no trace of the cuts is left: the region is meshed
// across the plane by one TetGen run, like the rest of the solid.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "partet/mesh_types.hpp"
#include "stages/partition.hpp"
#include "stages/piece.hpp"
#include "stages/seam_band.hpp"

namespace partet {

struct BandPartLinks;  // seam_chains.hpp

struct SeamStats {
  std::int64_t cut_vertices_removed = 0;  // vertices partitioning put on input edges
  std::int64_t cap_points_removed = 0;    // the caps' interior points (when healing)
  std::int64_t regions = 0;               // regions re-meshed (after growth)
  std::int64_t chains = 0;                // chains of cuts whose seams meet (seam_chains.hpp)
  std::int64_t tets_in = 0;               // tets replaced
  std::int64_t tets_out = 0;              // tets that replaced them
};

struct HealOptions {
  bool remove_cap_points = true;  // also the caps' interior points (healing); else only the cut vertices
  // Layers of tets added across the faces of the removed vertices' stars before re-meshing: the
  // stars' outer faces were shaped by the cap, and with a quality bound TetGen needs room beyond
  // them to grade the mesh across the plane as it would without a cut (2 when refining, else 0:
  // the seam zone's AMIPS average is then within 1% of TetGen's own mesh there; one layer of tets
  // sharing a vertex costs as much and leaves fertility's 2% worse).
  int layers = 0;
  // Drop the points no tet uses afterwards (the whole mesh); a band keeps them all (its points are
  // numbered as in the whole mesh, and the bulks use most of them).
  bool drop_points = true;
  // Each healed chain also finds its links (components, open faces: block_links), for a mesh left
  // spread, whose band is linked chain by chain (Welder::spread); an assembled mesh needs none.
  bool chain_links = false;
  // Each healed chain also says which of the band's tets it replaces (HealedChain::band_tets), for
  // a band whose tets are not all in chains: it is welded, and the chains put back into it.
  bool chain_band_tets = false;
  // A chain healed on another rank stays there (issue 22: rank 0 plans, it does not hold the
  // mesh): that rank keeps its tets for the writers and sends rank 0 only what numbering and
  // linking the mesh need (HealedChain::kept_on). Only with chain_links, for a band made of chains.
  bool keep_healed = false;
};

// Meshes a batch of closed surfaces (the regions around the seams, given as pieces with
// seam_region set), possibly in parallel; one outcome per surface, in order.
using RegionMesher = std::function<std::vector<PieceOutcome>(const std::vector<PieceSurface>&)>;

// The union of the stars of the removed vertices (the cut vertices; with remove_cap_points also
// the caps' interior points), grown by options.layers, is re-meshed, one connected part at a
// time, with its boundary fixed, except that the split fragments of input triangles are replaced
// by the input triangles themselves. Vertices that share a tet are healed together; all other
// parts heal in parallel, on any rank, in rounds planned on the mesh as it stands (parts where
// neighbouring cuts meet may take turns; see seam_rounds.hpp). Each chain of cuts whose seams
// meet (seam_chains.hpp) plans its rounds apart, and its new points are numbered together, chain
// by chain, so healing one chain at a time gives the same mesh as healing them all. A part that
// fails grows by a layer of tets (up to three times) first.
// Afterwards the mesh has none of the removed vertices and (with options.drop_points) no unused
// points; input vertices keep their relative order and coordinates, and re-meshed tets get piece -1. Throws the
// MeshingError of the region that failed, with the cut planes of that region.
SeamStats heal_seams(TetMesh& mesh, const SurfaceMesh& input, const SplitSurface& split, const HealOptions& options,
                     const RegionMesher& mesher);

// The cut planes of each chain of cuts whose seams meet (seam_chains.hpp) and still have vertices
// to remove in `mesh`, in the order of their lowest plane. A chain cut out and healed alone
// (seam_chain_band.hpp) heals as it does among the others.
std::vector<std::vector<int>> seam_chain_planes(const TetMesh& mesh, const SplitSurface& split,
                                                const HealOptions& options);
// The same from the links of every piece's band part (by piece; band_part_links), made with
// seam_band_spec(split, options): no welded band is needed. Also says where each chain's tets
// are: by piece, the chain of each part of its band part (-1: none), so that a chain can be
// welded from its pieces' shares (chain_share, weld_chain).
struct SeamChainPlan {
  std::vector<std::vector<int>> planes;         // by chain
  std::vector<std::vector<int>> chain_of_part;  // by piece, then part
  // The pieces with a part in chain c, ascending.
  std::vector<std::size_t> pieces_in(int c) const;
};
SeamChainPlan seam_chain_plan(const std::vector<BandPartLinks>& band_parts, const SplitSurface& split,
                              const HealOptions& options);

// The band healing with these options needs (seam_band.hpp): the stars of the vertices it
// removes, grown by the layers its first round adds and one more, so that a later round's region
// (grown from new tets) or a failed part's growth rarely meets the band's edge. Where one does,
// the edge's faces stay fixed, as the faces around any region do.
BandSpec seam_band_spec(const SplitSurface& split, const HealOptions& options);

}  // namespace partet
