// The output mesh left where its parts are (internal header): when only formats written from the
// parts are asked for on several ranks, rank 0 does not assemble the mesh. Each bulk stays on the rank that meshed
// it, numbered as in the assembled mesh, and its owner writes its rows; rank 0 keeps the healed
// band (when only the XDMF set is written, only the seam chains it healed: the others stay on the
// ranks that healed them, band_runs), the split surface's points and the points healing added. The connected solids ("region",
// numbered by their first tet) are found without the whole mesh: each block (a bulk, the band)
// labels its own components and names its open faces that another block may share; rank 0 joins
// the components that share a face.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "common/point_ids.hpp"
#include "partet/mesh_types.hpp"
#include "stages/info.hpp"
#include "stages/seam_band.hpp"

namespace partet {

// A block's connected components and the open faces it may share with another block.
struct BlockLinks {
  std::vector<std::int32_t> first_tet;            // per component, its first tet (ascending)
  std::vector<std::array<std::int64_t, 3>> keys;  // open faces, in the mesh's ids ascending; keys ascending
  std::vector<std::int32_t> component;            // per key: its tet's component
  std::vector<std::uint64_t> face;                // per key: the face, as 4 * tet + j
};

// An open face of a block and the tet across it in another block, in output ids (a row of the
// whole mesh's tets): what the TetGen .neigh file of a spread mesh needs besides each block's own
// neighbours.
struct FaceAcross {
  std::uint64_t face = 0;  // 4 * tet + j in its block
  std::int64_t tet = 0;
  bool operator<(const FaceAcross& o) const { return face < o.face; }
};

// The components of a block's tets across its own neighbours, numbered by first tet (label per
// tet), and its open faces (keyed by the mesh's ids of their points, through ids; in order of
// their keys, so that the blocks' faces are matched without a copy of them all): all of them
// when every_open_face, else those another block can share, the faces with a point that is no
// input vertex (ids from input_vertices on: cap faces) and the rim's faces (4 * tet + j).
BlockLinks block_links(const std::vector<Tet>& tets, const PointIds& ids, const std::vector<Tet>& neighbours,
                       bool every_open_face, std::int32_t input_vertices, const std::vector<std::uint64_t>& rim,
                       std::vector<std::int32_t>& label);

// A healed chain as a block of the band (add_healed_chains): where its tets start in the band,
// its links (every open face; keys in the band's ids) and its tets' components. With these the
// band of a spread mesh is linked chain by chain, from what the healing ranks found, instead of
// rank 0 finding the whole band's components and open faces again (Welder::spread).
struct BandChainLinks {
  std::int32_t first_tet = 0;  // its first row in the band
  std::int32_t tets = 0;
  BlockLinks links;
  std::vector<std::int32_t> label;  // here: per tet
  // A chain kept by the rank that healed it (HealedChain::kept_on): that rank, and the band's id
  // of each of its points (-1: no tet of it uses the point).
  int kept_on = -1;
  std::int32_t kept_as = -1;  // the index that rank keeps it by
  std::vector<std::int32_t> band_ids;
};

// The connected solids of a mesh made of blocks in row order (blocks[b] starts at row first_row[b]):
// per block, the solid (from 1, numbered by first row) of each of its components.
std::vector<std::vector<std::int32_t>> solids_of_blocks(const std::vector<BlockLinks>& blocks,
                                                        const std::vector<std::int64_t>& first_row);

// Per block, its faces shared with another block and the tet across each (by face): the faces
// whose keys two blocks share. Throws InternalError when three open faces are one triangle.
std::vector<std::vector<FaceAcross>> faces_across_blocks(const std::vector<BlockLinks>& blocks,
                                                         const std::vector<std::int64_t>& first_row);

// A tet's four neighbours as rows of the whole mesh (-1: none). In 64 bits: a spread mesh may have
// more than 2^31 tets, though each block numbers its own in 32.
using NeighbourRow = std::array<std::int64_t, 4>;

// Rows [from, from + count) of a block's neighbours in output ids: its own (local) neighbours
// moved to its first row, and the tets across its faces shared with other blocks; -1 elsewhere.
std::vector<NeighbourRow> neighbour_rows(const std::vector<Tet>& neighbours, std::int64_t first_row,
                                         const std::vector<FaceAcross>& across, std::size_t from, std::size_t count);

// One bulk of a spread mesh: its rows, and the bulk itself when rank 0 keeps it.
struct SpreadBulk {
  int piece = 0;
  bool here = false;                         // kept by rank 0 (in `block`), else by the rank that meshed it
  TetBlock block;                            // numbered as in the assembled mesh (block.ids; its Steiner points: the rows below)
  std::int64_t first_point = 0, points = 0;  // rows of its Steiner points
  std::int64_t first_tet = 0, tets = 0;      // rows of its tets
  std::vector<std::int32_t> solid;           // per component of its tets (block_links' order)
  std::vector<FaceAcross> across;            // its faces towards the band and other bulks
};

// A healed chain's rows in the band, when some chain is kept by the rank that healed it
// (HealOptions::keep_healed).
struct BandRun {
  int chain = 0;
  int rank = 0;  // that keeps its tets
  std::int64_t first_row = 0, tets = 0;
  std::int64_t first_here = 0;          // on rank 0: its first tet in band_tets
  std::vector<std::int32_t> solid;      // kept elsewhere: per component of its tets (block_links' order)
  std::vector<std::int64_t> point_ids;  // kept elsewhere: the mesh's id of each of its points (-1: unused)
};

// What rank 0 keeps of a mesh it does not assemble, and where every row is.
struct SpreadMesh {
  std::int64_t points = 0, tets = 0;     // the whole mesh's
  std::vector<Point3> split_points;      // rows [0, n): the split surface's points that stay
  std::int64_t first_healing_point = 0;  // rows of the points healing added
  std::vector<Point3> healing_points;
  std::vector<SpreadBulk> bulks;    // by piece
  std::int64_t first_band_tet = 0;  // the healed band's tets from this row, in compact ids (band_ids)
  std::vector<Tet> band_tets;
  std::vector<std::int64_t> band_point_ids;  // the mesh's ids of the band's compact ids from split_points.size() on
  std::vector<std::int32_t> band_piece, band_solid;
  std::vector<Tet> band_neighbours;  // local, as healing left them
  std::vector<FaceAcross> band_across;
  bool has_across = false;  // whether the blocks' faces across (band_across, SpreadBulk::across) were kept
  // The coordinates of the pieces' Steiner points the band's tets use (their rows are the
  // bulks', kept elsewhere; their ids: the first band_point_ids). For a .pvtu set's seam file.
  std::vector<Point3> band_steiner_points;
  // When some healed chain stayed on the rank that healed it: every chain's rows, in order (those
  // here in band_tets, one after another); else none, and band_tets are all the band's rows.
  std::vector<BandRun> band_runs;
  bool band_elsewhere() const { return !band_runs.empty(); }
  // The healed band's rows, here and elsewhere.
  std::int64_t band_rows() const { return tets - first_band_tet; }

  // The mesh's id of each of band_tets' ids (valid while band_point_ids is not changed).
  PointIds band_ids() const {
    return {static_cast<std::int32_t>(split_points.size()), 0, band_point_ids.data()};
  }
};

// The coordinates of point `id` as rank 0 keeps them: the split surface's points, those healing
// added, the Steiner points of the bulks it keeps and of the band. Throws InternalError for any
// other (a Steiner point only a bulk kept elsewhere uses).
Point3 point_of(const SpreadMesh& mesh, std::int64_t id);

// The piece values with tets, as pieces_in gives them for the assembled mesh: the seams' -1
// first (when healing re-meshed any), then the pieces ascending.
std::vector<int> piece_values(const SpreadMesh& mesh);

// The band's tets of one piece value, in row order and the mesh's ids, with their solids (and
// rows, when asked).
void band_tets_of(const SpreadMesh& mesh, int piece, std::vector<GlobalTet>& tets, std::vector<std::int32_t>& solid,
                  std::vector<std::int64_t>* rows = nullptr);

// The bounds of every point row of the mesh (all zero when there is none, as bounds_of gives
// them): rank 0's own, and those of the bulks kept elsewhere as `elsewhere` gives them.
Bounds bounds_of_rows(const SpreadMesh& mesh, const std::function<Bounds(const SpreadBulk&)>& elsewhere);

// A bulk's cell data as written: per tet its solid (through its component) and its piece.
void bulk_columns(const TetBlock& bulk, const SpreadBulk& place, std::vector<std::int32_t>& solid,
                  std::vector<std::int32_t>& piece);

}  // namespace partet
