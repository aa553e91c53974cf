// The point numbering of the assembled mesh (Welder::assemble), made from the healed band alone,
// before any bulk comes back: a bulk can be numbered wherever it is kept.
#pragma once
#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include "common/point_ids.hpp"
#include "partet/mesh_types.hpp"
#include "stages/seam_band.hpp"

namespace partet {

// Throws MeshingError when a mesh held in one process would have more than 2^31 points or tets:
// its ids are int32. A mesh left on its ranks may have more of both: its ids, rows and neighbours
// are 64-bit (each block of it numbers its own tets and points in 32).
void check_int32_sizes(std::size_t tets, std::size_t points);

// Welded ids: the split surface's points [0, S), then piece p's Steiner points from
// S + steiner_before[p], then the points healing added. Band ids: the split surface's points, then
// each piece's band Steiner points in piece order, then the points healing added. A bulk numbers
// the split surface's points as welded, and its piece's Steiner point i as S + i.
struct AssemblyPoints {
  std::int32_t split_points = 0;                        // S
  std::vector<std::int64_t> steiner_counts;             // per piece: its Steiner points (band and bulk)
  std::vector<std::vector<std::int32_t>> band_steiner;  // per piece: its band's Steiner points, as piece indices
  std::vector<bool> band_used_before;                   // per band id before healing: a band tet uses it
  std::vector<bool> referenced;                         // per split point: some piece's surface has it
};

// One bulk's share of the numbering: all its keeper needs to number the bulk's points (split
// surface's as welded, its piece's Steiner point i as S + i) as in the assembled mesh. A bulk
// keeps 32-bit ids, compact: the split surface's points that stay as in the mesh [0, S'), its
// own Steiner points that stay from S' on; ids() gives the mesh's (64-bit) id of each.
struct BulkNumbering {
  std::int32_t split_points = 0;              // S
  // The split surface's points that go, ascending: one list, which every bulk's share holds (as
  // long as the seams' removed vertices: a copy per bulk was 53 MB on rank 0 at 2.74M input faces
  // and 64 pieces, and as much again in the message to the owners).
  std::shared_ptr<const std::vector<std::int32_t>> dropped_split = std::make_shared<const std::vector<std::int32_t>>();
  std::int64_t first_steiner = 0;             // the mesh's id of the piece's first Steiner point that stays
  std::vector<std::int32_t> dropped_steiner;  // the piece's Steiner points that go (as i), ascending
  // The split surface's points that stay: S'.
  std::int32_t kept_split() const { return split_points - static_cast<std::int32_t>(dropped_split->size()); }
  // The compact id of a bulk point; -1 when it goes. Most points are input vertices, below every
  // point that goes, and most pieces lose no Steiner point: those need no search.
  std::int32_t operator()(std::int32_t v) const {
    if (v < split_points) {
      if (dropped_split->empty() || v < dropped_split->front()) return v;
    } else if (dropped_steiner.empty()) {
      return kept_split() + (v - split_points);
    }
    return searched(v);
  }
  // The mesh's id of each compact id.
  PointIds ids() const { return {kept_split(), first_steiner - kept_split(), nullptr}; }
  // How many of the split surface's first n points stay (the assembled ids below that of point n).
  std::int32_t split_kept_below(std::int32_t n) const;

 private:
  std::int32_t searched(std::int32_t v) const;
};

// A bulk's share as it goes to where the bulk is kept: its piece, and the id there of the piece's
// Steiner point 0 (a rank that split the piece numbered them from its own count of split points).
struct BulkShare {
  std::int32_t piece = 0;
  std::int32_t first_steiner = 0;
  BulkNumbering numbering;
};

// Numbers a bulk in place, where it is kept, as in the assembled mesh: its tets' points through
// its share (its Steiner point i given as first_steiner + i) in compact ids, bulk.ids the mesh's
// id of each, and only its Steiner points that stay, in order (the first is the mesh's point
// share.first_steiner). Then bulk.numbered. Throws InternalError when a tet uses a point that
// goes (the numbering was not made for this bulk).
void number_bulk(TetBlock& bulk, const BulkNumbering& share, std::int32_t first_steiner);

// Where each welded point goes in the assembled mesh. Healing re-meshes band tets only and keeps
// the band's faces towards the bulks; a point a bulk shares with the band lies on such a face (the
// tets around a point are connected through its faces). So a point goes exactly when no tet uses
// it: the band used it before healing and no longer does, or no piece ever had it (an input
// vertex that no triangle has).
class AssemblyNumbering {
 public:
  // For a healed band (tets in band ids; points: the band's, then healing's). drop_unused false:
  // every point stays (healing goes on over the assembled mesh, which then drops them).
  // used_elsewhere: the band's points that tets of it kept on other ranks use (healed chains kept
  // where they healed), in any order.
  AssemblyNumbering(AssemblyPoints points, const TetMesh& healed_band, bool drop_unused,
                    const std::vector<std::int32_t>& used_elsewhere = {});

  std::int64_t point_count() const { return kept_; }
  // The welded id of piece p's Steiner point i, and of a band point.
  std::int64_t welded_steiner(std::size_t p, std::int64_t i) const { return split_points_ + steiner_before_[p] + i; }
  std::int64_t welded_of_band(std::int32_t v) const;
  std::int64_t welded_count() const { return welded_; }
  std::int64_t healing_first_welded() const { return split_points_ + steiner_before_.back(); }
  std::int64_t healing_first_band() const { return healing_first_band_; }
  // The id in the assembled mesh of a welded point (-1: it goes), and of a band point.
  std::int64_t of_welded(std::int64_t w) const;
  // Calls f(welded id, assembled id) for each point in [from, to) that stays, in order.
  template <class F>
  void for_each_kept(std::int64_t from, std::int64_t to, F f) const {
    auto gone = std::lower_bound(dropped_.begin(), dropped_.end(), from);
    std::int64_t shift = gone - dropped_.begin();
    for (std::int64_t w = from; w < to; ++w) {
      if (gone != dropped_.end() && *gone == w) {
        ++gone, ++shift;
        continue;
      }
      f(w, w - shift);
    }
  }
  std::int64_t of_band(std::int32_t v) const { return of_welded(welded_of_band(v)); }
  // What piece p's bulk needs to be numbered where it is kept.
  BulkNumbering for_bulk(std::size_t p) const;

 private:
  std::int32_t split_points_;
  std::vector<std::int64_t> steiner_before_;  // per piece and one past the last
  std::vector<std::int64_t> band_before_;     // band Steiner points of earlier pieces, likewise
  std::vector<std::vector<std::int32_t>> band_steiner_;
  std::int64_t healing_first_band_ = 0;
  std::int64_t welded_ = 0;            // welded points
  std::vector<std::int64_t> dropped_;  // the welded ids that go, ascending
  std::shared_ptr<const std::vector<std::int32_t>> dropped_split_;  // those of them below split_points_
  std::int64_t kept_ = 0;
};

}  // namespace partet
