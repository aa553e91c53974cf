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
#include <vector>

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

// Every piece's band in one process, the pieces trading crossings with their neighbours (piece
// p - 1 and p + 1) until none grows. tets[p] and neighbours[p] are piece p's.
std::vector<std::vector<std::int8_t>> mark_bands(const std::vector<const std::vector<Tet>*>& tets,
                                                 const std::vector<const std::vector<Tet>*>& neighbours,
                                                 const BandSpec& spec);

}  // namespace partet
