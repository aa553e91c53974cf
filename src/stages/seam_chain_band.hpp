// A chain's band (internal header): the part of the band that one chain of cuts heals
// (seam_chains.hpp), welded from its pieces' shares of their band parts (or cut out of the welded
// band) with ids of its own and with what its healing reads of the input and of the split
// surface, so that it can heal anywhere (on a rank of its own, which also welds it); and the band
// with the healed chains put back. The ids keep their order (a chain's points are numbered by their ids in the
// band, ascending), so a chain heals as it would in the band: its regions reach TetGen as the
// same surfaces.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "partet/errors.hpp"
#include "partet/mesh_types.hpp"
#include "stages/partition.hpp"
#include "stages/seam_healing.hpp"
#include "stages/spread_mesh.hpp"

namespace partet {

struct ChainBand {
  std::vector<int> planes;               // the chain's cut planes
  SurfaceMesh input;                     // the input triangles its healing may put back (no points)
  SplitSurface split;                    // its cut vertices, cap points and split triangles, local ids
  TetMesh mesh;                          // its tets (and their pieces), local ids
  std::vector<std::int32_t> global_ids;  // by local point: its id in the band, ascending
  std::vector<std::int32_t> band_tets;   // the band's tets it holds, ascending
};

// Where a chain is: its tets in the band and its split triangles (those with a cut vertex on its
// planes), ascending.
struct ChainParts {
  std::vector<std::int32_t> tets, split_triangles;
};

// The parts of each chain (the planes of whole chains, as seam_chain_planes lists them): its tets
// are those within the band's depth (seam_band_spec) of the vertices on its planes that healing
// with these options removes. One search from every chain at once: chains never meet.
std::vector<ChainParts> chain_parts(const TetMesh& band, const SplitSurface& split,
                                    const std::vector<std::vector<int>>& chains, const HealOptions& options);

// The chain of these planes and parts (chain_parts), cut out of `band`: what weld_chain gives
// without the welded band (the tests compare them).
ChainBand cut_out_chain(const TetMesh& band, const SurfaceMesh& input, const SplitSurface& split,
                        const std::vector<int>& planes, ChainParts&& parts);

// The split triangles of each chain (the planes of whole chains): those with a cut vertex on its
// planes, ascending.
std::vector<std::vector<std::int32_t>> chain_split_triangles(const SplitSurface& split,
                                                             const std::vector<std::vector<int>>& chains);

// One piece's tets in one chain, cut out of its band part wherever that is kept, in the welded
// band's ids: what the piece gives the rank that heals the chain (issue 22).
struct ChainShare {
  int chain = -1;
  int piece = 0;
  std::vector<std::int32_t> band_tets;  // the band's ids of its tets, ascending
  std::vector<Tet> tets;                // by place in point_ids (so that rank 0 welds without searching)
  std::vector<Tet> neighbours;          // within the share, -1 elsewhere
  std::vector<std::int32_t> point_ids;  // the band's ids of the points its tets use, ascending
  // The coordinates of the last points.size() of them: its Steiner points. The split surface's
  // points come with the chain's split (ChainSplit), from where the split surface is.
  std::vector<Point3> points;
};

// A piece's band part's tets by chain (chain_of_part: the piece's SeamChainPlan::chain_of_part):
// the chains it has tets in, ascending, and those tets, ascending.
struct BandPartChains {
  std::vector<int> chains;
  std::vector<std::vector<std::int32_t>> tets;  // by place in `chains`
  std::vector<std::int32_t> at;                 // per tet of the part: its place in its chain's tets
};
BandPartChains band_part_chains(const TetBlock& band, const std::vector<int>& chain_of_part);

// The share of the i-th chain of `in_chains` (band_part_chains) of a piece's band part
// (Welder::band_part); `place` where the part goes in the band (Welder::band_part_places).
ChainShare chain_share(const TetBlock& band, const BandPartChains& in_chains, std::size_t i,
                       const BandPartPlace& place);

// What healing reads of the split surface for one chain, in the band's ids: its planes, the
// split surface's id ranges (input vertices, cut vertices, caps' points), the split surface's
// points its tets may use with their coordinates, the planes of the cut vertices and caps' points
// among them, its split triangles and their input triangles (in first-use order). Made where the
// split surface is (rank 0) without the chain's tets, so that any rank can weld the chain from
// shares that never pass through rank 0.
struct ChainSplit {
  std::vector<int> planes;
  std::int32_t first_cut = 0, first_cap = 0, end_caps = 0;
  std::vector<std::int32_t> point_ids;  // ascending: every one the chain's shares use, perhaps more
  std::vector<Point3> points;           // their coordinates
  std::vector<std::int32_t> cut_vertices, cut_vertex_plane;  // ids ascending; their planes
  std::vector<std::int32_t> cap_points, cap_point_plane;     // ids ascending; their planes
  std::vector<Triangle> triangles;                           // its split triangles
  std::vector<std::int32_t> parent;                          // per split triangle: its place in input_triangles
  std::vector<Triangle> input_triangles;
};

// A chain before welding: its pieces' shares (by their first tet in the band, as chain_shares
// orders them; weld_chain takes them in any order) and its split.
struct ChainShares {
  std::vector<ChainShare> shares;
  ChainSplit split;
};

// The split of the chain of these planes and split triangles (chain_split_triangles), from the
// split surface's points `ids` (ascending) its tets may use: those of its pieces' band parts
// (Welder::band_split_points), or the chain's own; split_points their coordinates by id.
ChainSplit chain_split(const SplitSurface& split, const SurfaceMesh& input, const std::vector<Point3>& split_points,
                       const std::vector<int>& planes, const std::vector<std::int32_t>& triangles,
                       const std::vector<std::int32_t>& ids);
// The chain as its pieces' shares (in any order) and its split, ready to weld anywhere. Throws
// InternalError when the shares are of several chains.
ChainShares chain_shares(std::vector<ChainShare>&& shares, ChainSplit&& split);
// The band's tets the chain holds, ascending (weld_chain's band_tets).
std::vector<std::int32_t> band_tets_of(const ChainShares& chain);

// The chain welded from its shares: the chain cut_out_chain cuts out of the welded band, without
// the welded band. Throws InternalError when the shares overlap or the split lacks a point.
ChainBand weld_chain(ChainShares&& chain);

// A chain healed, wherever that was: in its ids, its points then new_points.
// Its tets are in order_band_tets' order, with their neighbours within the chain (-1 at its edge):
// its ids keep the band's order, so this is their order in the band too, and rank 0 puts the
// chains into the band one after another without sorting or connecting its tets again.
struct HealedChain {
  std::vector<std::int32_t> global_ids;  // by point of its own before new_points: its id in the band
  std::vector<Point3> new_points;        // the points its healing added
  std::vector<Tet> tets;
  std::vector<Tet> neighbours;
  std::vector<std::int32_t> piece;      // when the band has pieces
  BlockLinks links;                     // block_links of its tets (every open face, keys in its ids)
  std::vector<std::int32_t> label;      // per tet: its component in links
  std::vector<std::int32_t> band_tets;  // when asked (chain_band_tets): the band's tets it replaces, ascending
  SeamStats stats;
  std::optional<Failure> failure;  // of the MeshingError its healing threw (then nothing else)
  double seconds = 0;
  // Kept by the rank that healed it (HealOptions::keep_healed): that rank, and here only its
  // points (global_ids, new_points), links and stats, its tet count and the points its tets use;
  // tets, neighbours, piece and label stay there.
  int kept_on = -1;
  std::int32_t kept_as = -1;  // the index that rank keeps it by
  std::int32_t kept_tets = 0;
  std::vector<char> used;  // per point of its own: whether a tet uses it
};

// What rank 0 is sent of a chain healed and kept elsewhere (HealedChain::kept_on): the chain
// without its tets.
HealedChain kept_elsewhere(const HealedChain& chain, int rank, std::int32_t index);

// Heals a chain cut out of the band; its mesh goes into the result. A MeshingError becomes the
// result's failure.
HealedChain heal_chain(ChainBand&& chain, const HealOptions& options, const RegionMesher& mesher);

// The band with its chains (cut out of it, in the order of seam_chain_planes; per chain, the
// band's tets it was cut from) healed and put back: their tets replace those they were cut from,
// and the points healing added follow the band's, chain after chain, as heal_seams numbers them.
// The tets are then in order_band_tets' order, as the band healed in one piece.
void put_back_chains(TetMesh& band, const std::vector<std::vector<std::int32_t>>& chain_tets,
                     std::vector<HealedChain>&& healed);
// The chains into a band of points alone (Welder::band_points) when they hold every tet of the
// band (each tet of a band part is in the chain of its part, or in the one chain -1's share makes,
// put back unhealed): the band's tets are the chains', chain after chain, each in its own order
// with its own neighbours (chains share no face). So the band is the same however many ranks
// healed it, and made in one pass. Returns each chain's links in the band's ids when `links` (the
// chains were healed with HealOptions::chain_links), else none.
std::vector<BandChainLinks> add_healed_chains(TetMesh& band, std::vector<HealedChain>&& healed, bool links);

// Orders tets by their vertices (and neighbours to match): a healed chain's, or a band's healed
// in one piece (the same whether it healed on one rank or on several).
void order_band_tets(TetMesh& band);

}  // namespace partet
