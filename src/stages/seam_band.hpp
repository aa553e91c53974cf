// Seam bands (internal header): which tets of each piece seam healing may re-mesh. Healing
// re-meshes only the tets around the vertices it removes (the cut vertices, and with healing the
// caps' interior points): on bob refined to 2.74M faces, 4.5% of the tets at 16 pieces and 13% at
// 64. A piece's band is the tets within a few layers of those vertices; the rest, its bulk,
// healing never touches. The layers reach across the caps into the neighbouring pieces, so the
// pieces trade the cap faces they reached until no band grows: each piece needs only its own
// tets and its neighbours' crossings, which is what lets the bulk stay where the piece was meshed.
// The Welder (merge.hpp) splits the pieces and welds the bands alone.
#pragma once
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "common/point_ids.hpp"
#include "partet/mesh_types.hpp"
#include "stages/topology.hpp"

namespace partet {

// What makes the band: ids in global numbering (the split surface's points below
// split_point_count, Steiner points above), the removed vertices [first_removed, end_removed), and
// how many layers of tets across faces the band reaches beyond their stars.
struct BandSpec {
  std::int32_t input_vertex_count = 0;
  std::int32_t split_point_count = 0;
  std::int32_t first_removed = 0, end_removed = 0;
  int layers = 1;
  bool removes(std::int32_t v) const { return v >= first_removed && v < end_removed; }
  // On a cut plane: split points that are not input vertices (no plane passes through one).
  bool on_planes(std::int32_t v) const { return v >= input_vertex_count && v < split_point_count; }
};

// A cap face a piece's band reached: its key in global ids and the layer of the tet reaching it.
struct CapCrossing {
  FaceKey key;
  std::int32_t depth;
};

// Which tets of one piece (tets in global ids, neighbours within the piece) are in its band.
class BandMarks {
 public:
  BandMarks(const std::vector<Tet>& tets, const std::vector<Tet>& neighbours, const BandSpec& spec);
  // The cap faces this piece's band reached below its last layer (for the neighbouring pieces).
  std::vector<CapCrossing> crossings() const;
  // Goes on from the cap faces a neighbour reached (one layer further on this side). Returns
  // whether the band grew.
  bool enter(const std::vector<CapCrossing>& from_neighbour);
  // The keys of the open cap faces whose tets are outside the band, ascending: where a
  // neighbour's crossings would make it grow.
  std::vector<FaceKey> cap_faces_outside() const;
  // Per tet: -1 outside the band, else its layer (0: it has a removed vertex).
  const std::vector<std::int8_t>& depth() const { return depth_; }
  std::vector<std::int8_t> take_depth() { return std::move(depth_); }

 private:
  void spread(std::vector<std::int32_t> from);
  const std::vector<Tet>& neighbours_;
  int layers_;
  std::vector<std::int8_t> depth_;
  struct OpenCapFace {
    FaceKey key;
    std::int32_t tet;
    bool operator<(const OpenCapFace& o) const { return key < o.key; }
  };
  std::vector<OpenCapFace> cap_faces_;  // the piece's open faces that may lie on a cap, by key
};

// Part of a piece's mesh in global vertex ids: its band, its bulk, or the whole piece.
struct TetBlock {
  bool in = false;
  bool numbered = false;  // a bulk numbered as in the assembled mesh (number_bulk), where it was kept
  std::vector<Point3> steiner_points;
  std::vector<Tet> tets;           // global ids; Steiner point s of the piece is the first Steiner id + s
  PointIds ids;                    // numbered: the mesh's id of each id in tets (its Steiner points from `from` on)
  std::vector<Tet> neighbours;     // local tet ids
  std::vector<std::uint64_t> rim;  // a bulk's faces towards its band (4 * tet + j)
};

// What one piece's band part tells of the chains, wherever it is kept: its parts joined through
// faces within the piece, the vertices to remove each holds, and the open faces on the planes
// each has. A neighbouring piece's band part with the same face is joined to it across the cap,
// so these are all that the chains need of the band (issue 22: a chain can be found, and
// healed, without the welded band). seam_chains.hpp makes and joins them.
struct BandPartLinks {
  std::vector<std::vector<std::int32_t>> removed;           // per part: its vertices to remove, ascending
  std::vector<std::pair<FaceKey, std::int32_t>> cap_faces;  // open faces on the planes and their parts, by key
  std::vector<std::int32_t> tets;                           // per part: how many tets it has
};

// A piece's mesh split into its band and its bulk. Split where the piece was meshed (one layer:
// the piece alone decides its band), the bulk stays there and the rest travels to the welder.
struct PieceBand {
  int index = 0;
  std::int32_t first_steiner = 0;          // the id of the piece's first Steiner point in both blocks
  TetBlock band;                           // its Steiner points renumbered: band point b is first_steiner + b
  TetBlock bulk;                           // every Steiner point of the piece, with its own id
  std::vector<std::int32_t> band_steiner;  // per band Steiner point: its index in the piece
  std::vector<std::int32_t> band_tets;     // per band tet: its place in the piece
  std::vector<CapCrossing> crossings;      // BandMarks::crossings
  std::vector<FaceKey> cap_faces_outside;  // BandMarks::cap_faces_outside
  std::optional<BandPartLinks> links;      // its band's (band_part_links), made where it was split
  std::int64_t bulk_tets = 0, bulk_steiner_points = 0;  // the bulk's, also once it is elsewhere
  // The band part kept where it was split (KeptBandParts): its tets, neighbours and band_tets
  // stay there (band keeps its Steiner points), and these tell the welder what it needs of them.
  bool band_kept = false;
  std::int64_t band_tet_count = 0;
  std::vector<std::int32_t> band_split_points;  // the split surface's points its tets use, ascending
};

// Where a piece's band part goes in the welded band (Welder::finish_band): the band's id of its
// first tet, and the ids of its first Steiner point in the part and in the band.
struct BandPartPlace {
  int piece = 0;
  std::int32_t first_tet = 0;
  std::int32_t steiner_from = 0, steiner_to = 0;
};

// A piece's mesh in global ids: its surface points through global_ids, its Steiner point s as
// first_steiner + s. Frees the result's arrays.
TetBlock in_global_ids(PieceTetMesh&& result, const std::vector<std::int32_t>& global_ids, std::int32_t first_steiner);

// Splits a piece's block by its band marks (depth >= 0: band): both sides in piece order, their
// neighbours renumbered on their side (-1 across), the bulk's faces towards the band in its rim.
PieceBand split_by_depth(TetBlock&& whole, const std::vector<std::int8_t>& depth, std::int32_t first_steiner);

// A piece's block split by the band it decides alone (one layer, as it arrives): its band marks,
// crossings and bulk's open cap faces, then split_by_depth; spec.split_point_count is the id its
// Steiner points start from.
PieceBand split_alone(TetBlock&& whole, const BandSpec& spec);

// The split where the piece was meshed, one layer (spec.layers == 1): spec.split_point_count is
// the id its Steiner points start from, which may be any id above every split point's (where the
// closure is still adding cap points, the final one is not known yet).
PieceBand split_where_meshed(PieceTetMesh&& result, const std::vector<std::int32_t>& global_ids, const BandSpec& spec);

// A split piece joined again: its band (its Steiner points renumbered from first_steiner, as
// band_steiner maps them to the piece's) and its bulk, every tet back at its place in the piece
// (band_tets: the band's), with the neighbours between them restored.
TetBlock join_band_and_bulk(TetBlock&& band, TetBlock&& bulk, const std::vector<std::int32_t>& band_steiner,
                            const std::vector<std::int32_t>& band_tets, std::int32_t first_steiner);

// A piece's band as the welder holds it, to grow by the cap faces its neighbours' bands reached:
// with the bulk, wherever that is kept, it is the piece split again (grow_band).
struct BandToGrow {
  int index = 0;
  BandSpec spec;  // spec.split_point_count: the id the piece's Steiner points start from
  TetBlock band;  // its Steiner points renumbered (band point b is spec.split_point_count + b)
  std::vector<std::int32_t> band_steiner, band_tets;  // as PieceBand has them
  std::vector<CapCrossing> crossings;                 // its neighbours': the lower piece's, then the upper's
  bool band_kept = false;  // its band part is kept with the bulk (KeptBandParts): band and its maps are not here
};

// The piece's band grown by its neighbours' crossings, and its bulk without the tets that
// joined the band: the piece's block joined again, marked anew (its own band, then the
// crossings) and split. Where the bulk is kept elsewhere this runs there, and only the band
// travels. (No crossings and cap faces in the result: a band grows once, the crossings reaching
// only the last layer.)
PieceBand grow_band(BandToGrow&& band, TetBlock&& bulk);

// Every piece's band in one process, the pieces trading crossings with their neighbours (piece
// p - 1 and p + 1) until none grows. tets[p] and neighbours[p] are piece p's.
std::vector<std::vector<std::int8_t>> mark_bands(const std::vector<const std::vector<Tet>*>& tets,
                                                 const std::vector<const std::vector<Tet>*>& neighbours,
                                                 const BandSpec& spec);

}  // namespace partet
