#include "stages/merge.hpp"

#include <algorithm>
#include <map>
#include <set>

#include "common/log.hpp"
#include "common/stage_timer.hpp"
#include "partet/errors.hpp"
#include "stages/kept_band_parts.hpp"
#include "stages/tet_region.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

// The tets with a face that may lie on a cap: three vertices that are not input vertices (no cut
// plane passes through an input vertex). The input's own boundary faces, most of the open faces,
// need no matching.
bool may_touch_cap(const Tet& t, std::int32_t input_vertex_count) {
  int on_planes = 0;
  for (auto v : t) on_planes += v >= input_vertex_count;
  return on_planes >= 3;
}

std::vector<std::int32_t> tets_touching_caps(const TetMesh& mesh, std::int32_t input_vertex_count) {
  std::vector<std::int32_t> touching;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    if (may_touch_cap(mesh.tets[t], input_vertex_count)) touching.push_back(static_cast<std::int32_t>(t));
  return touching;
}

// Room reserved beyond the welded mesh's size, a fraction of it: seam healing can add tets and
// points, and an array that outgrows its capacity is copied into one twice its size while the old
// one still exists. Reserved pages cost no memory until they are written.
constexpr std::size_t kHealingRoom = 8;  // 1/8

template <class T>
void reserve_with_room(std::vector<T>& array, std::size_t size) {
  array.reserve(size + size / kHealingRoom + 1024);
}

// A face of a bulk towards its band: its key and where the bulk has it (4 * tet + j).
struct RimFace {
  FaceKey key;
  std::uint64_t slot;
  bool operator<(const RimFace& o) const { return key < o.key; }
};

// Joins every rim face to the band's tet (from band_base on) that has it open. Only the rim is
// sorted, not every open face of the band (most are the solid's boundary).
void join_rim(TetMesh& mesh, std::int32_t band_base, std::vector<RimFace> rim) {
  std::sort(rim.begin(), rim.end());
  std::size_t joined = 0;
  for (std::size_t t = static_cast<std::size_t>(band_base); t < mesh.tets.size(); ++t)
    for (int j = 0; j < 4; ++j) {
      if (mesh.neighbours[t][j] >= 0) continue;
      const RimFace probe{FaceKey(outward_face(mesh.tets[t], j)), 0};
      const auto it = std::lower_bound(rim.begin(), rim.end(), probe);
      if (it == rim.end() || !(it->key == probe.key)) continue;
      mesh.neighbours[t][j] = static_cast<std::int32_t>(it->slot / 4);
      mesh.neighbours[it->slot / 4][it->slot % 4] = static_cast<std::int32_t>(t);
      ++joined;
    }
  if (joined != rim.size()) throw InternalError("a face between a piece's bulk and its band was lost in healing");
}

// Steiner ids (from `from` on, the split's points below) renumbered to start at `to`.
void move_steiner_ids(std::vector<Tet>& tets, std::int32_t from, std::int32_t to) {
  if (from == to) return;
  for (Tet& t : tets)
    for (auto& v : t)
      if (v >= from) v = to + (v - from);
}

[[noreturn]] void mismatch(int piece, const std::string& what) {
  throw InternalError("the result of piece " + std::to_string(piece) + " " + what);
}

}  // namespace

PieceBand BulkStore::take_band(int piece) {
  throw InternalError("no band part of piece " + std::to_string(piece) + " is kept with its bulk");
}

std::vector<ChainShare> BulkStore::shares(int) { return {}; }

Welder::Welder(const SplitSurface& split, const std::vector<PieceSurface>& pieces)
    : split_(split),
      pieces_(pieces),
      first_steiner_(static_cast<std::int32_t>(split.points.size())),
      blocks_(pieces.size()),
      bulks_(pieces.size()),
      stored_(pieces.size()),
      band_elsewhere_(pieces.size()),
      band_steiner_(pieces.size()),
      band_tets_(pieces.size()),
      made_links_(pieces.size()),
      crossings_(pieces.size()),
      bulk_cap_faces_(pieces.size()) {}

void Welder::split_on_arrival(const BandSpec& spec) {
  if (spec.layers > 1) return;
  split_on_arrival_ = spec;
  split_on_arrival_->split_point_count = first_steiner_;
}

bool Welder::has(int piece) const {
  return piece >= 0 && static_cast<std::size_t>(piece) < blocks_.size() && blocks_[piece].in;
}

void Welder::add(PieceTetMesh&& result) {
  const int p = result.index;
  if (p < 0 || static_cast<std::size_t>(p) >= pieces_.size() || pieces_[p].index != p ||
      result.surface_point_count != static_cast<std::int32_t>(pieces_[p].global_ids.size()))
    mismatch(p, "does not match its piece");
  if (blocks_[p].in) mismatch(p, "arrived twice");
  note_surface(static_cast<std::size_t>(p));
  TetBlock whole = in_global_ids(std::move(result), pieces_[p].global_ids, first_steiner_);
  if (!split_on_arrival_) {
    blocks_[p] = std::move(whole);
    return;
  }
  PieceBand split = split_alone(std::move(whole), *split_on_arrival_);  // its split_point_count is first_steiner_
  bulks_[p] = std::move(split.bulk);
  install_band(static_cast<std::size_t>(p), std::move(split));
  store_bulk(static_cast<std::size_t>(p));
}

// The pieces split on arrival take their neighbours' crossings: a piece whose bulk has an open cap
// face a neighbour's band reached is split again with the tets across added (one exchange does:
// with one layer, the tets a crossing reaches are the last layer).
void Welder::take_crossings() {
  const std::size_t k = blocks_.size();
  for (std::size_t p = 0; p < k; ++p) {
    std::vector<CapCrossing> from;  // the lower neighbour's, then the upper's
    if (p > 0) from = crossings_[p - 1];
    if (p + 1 < k) from.insert(from.end(), crossings_[p + 1].begin(), crossings_[p + 1].end());
    const std::vector<FaceKey>& outside = bulk_cap_faces_[p];
    const bool grows = std::any_of(from.begin(), from.end(), [&](const CapCrossing& c) {
      return std::binary_search(outside.begin(), outside.end(), c.key);
    });
    if (grows) grow_piece(p, std::move(from));
  }
  crossings_.assign(k, {});
  bulk_cap_faces_.assign(k, {});
}

void Welder::grow_piece(std::size_t p, std::vector<CapCrossing>&& crossings) {
  StoredBulk& stored = stored_[p];
  const bool where_kept = stored.stored && stored.store->grows_bands();
  if (!where_kept) band_here(p);
  BandToGrow band{static_cast<int>(p),         *split_on_arrival_,       std::move(blocks_[p]),
                  std::move(band_steiner_[p]), std::move(band_tets_[p]), std::move(crossings)};
  PieceBand grown;
  if (where_kept) {
    // The band in the owner's ids and back: the bulk numbers the piece's Steiner points from there.
    // A band part kept there too stays there: only the crossings travel.
    band.spec.split_point_count = stored.first_steiner;
    if (band_elsewhere_[p].kept)
      band.band = Block(), band.band_steiner.clear(), band.band_tets.clear(), band.band_kept = true;
    move_steiner_ids(band.band.tets, first_steiner_, stored.first_steiner);
    grown = stored.store->grow(std::move(band));
    if (grown.index != static_cast<int>(p) || grown.bulk.in)
      mismatch(static_cast<int>(p), "came back from its band's growth as another piece or with its bulk");
    move_steiner_ids(grown.band.tets, stored.first_steiner, first_steiner_);
    stored.tets = static_cast<std::size_t>(grown.bulk_tets);
    stored.steiner_points = static_cast<std::size_t>(grown.bulk_steiner_points);
  } else {
    band.spec.split_point_count = first_steiner_;
    grown = grow_band(std::move(band), std::move(bulk_here(p)));
    bulks_[p] = std::move(grown.bulk);
  }
  if (grown.band_kept && !where_kept) mismatch(static_cast<int>(p), "grew here with a band part kept elsewhere");
  band_elsewhere_[p] = {grown.band_kept, static_cast<std::size_t>(grown.band_tet_count),
                        std::move(grown.band_split_points)};
  blocks_[p] = std::move(grown.band);
  blocks_[p].in = true;
  band_steiner_[p] = std::move(grown.band_steiner);
  band_tets_[p] = std::move(grown.band_tets);
  made_links_[p] = std::move(grown.links);
  if (!stored.stored) store_bulk(p);
}

PieceTetMesh Welder::take_back(int p) {
  if (!has(p)) mismatch(p, "was never welded");
  if (bulks_[p].in) rejoin(static_cast<std::size_t>(p));
  Block& block = blocks_[p];
  const std::vector<std::int32_t>& global_ids = pieces_[p].global_ids;
  const auto surface_count = static_cast<std::int32_t>(global_ids.size());
  PieceTetMesh result;
  result.index = p;
  result.surface_point_count = surface_count;
  result.mesh.tets = std::move(block.tets);
  for (Tet& t : result.mesh.tets)
    for (auto& v : t)
      v = v < first_steiner_ ? static_cast<std::int32_t>(std::lower_bound(global_ids.begin(), global_ids.end(), v) -
                                                         global_ids.begin())
                             : surface_count + (v - first_steiner_);
  result.mesh.neighbours = std::move(block.neighbours);
  result.mesh.steiner_points = std::move(block.steiner_points);
  block = Block();
  return result;
}

TetMesh Welder::finish(std::vector<Point3> split_points) {
  for (std::size_t p = 0; p < blocks_.size(); ++p)
    if (bulks_[p].in) rejoin(p);
  return weld_blocks(std::move(split_points), blocks_);
}

TetMesh Welder::weld_blocks(std::vector<Point3> split_points, std::vector<Block>& blocks) const {
  if (split_points.size() != static_cast<std::size_t>(first_steiner_))
    throw InternalError("the welder was given " + std::to_string(split_points.size()) + " split points, not " +
                        std::to_string(first_steiner_));
  std::size_t tet_total = 0, steiner_total = 0;
  for (std::size_t p = 0; p < blocks.size(); ++p) {
    if (!blocks[p].in) mismatch(static_cast<int>(p), "is missing");
    tet_total += blocks[p].tets.size();
    steiner_total += blocks[p].steiner_points.size();
  }
  check_int32_sizes(tet_total, split_points.size() + steiner_total);
  TetMesh mesh;
  mesh.points = std::move(split_points);
  // The split reserved room (split_at_planes), so this copies every point only when that room
  // cannot take the Steiner points and what healing adds (reserve keeps a large enough array).
  reserve_with_room(mesh.points, mesh.points.size() + steiner_total);
  reserve_with_room(mesh.tets, tet_total);
  reserve_with_room(mesh.neighbours, tet_total);
  reserve_with_room(mesh.piece, tet_total);
  for (std::size_t p = 0; p < blocks.size(); ++p) {
    Block& block = blocks[p];
    // Earlier pieces' Steiner points come first; tets follow each other in piece order.
    const auto steiner_shift = static_cast<std::int32_t>(mesh.points.size()) - first_steiner_;
    const auto tet_base = static_cast<std::int32_t>(mesh.tets.size());
    mesh.points.insert(mesh.points.end(), block.steiner_points.begin(), block.steiner_points.end());
    for (Tet t : block.tets) {
      for (auto& v : t)
        if (v >= first_steiner_) v += steiner_shift;
      mesh.tets.push_back(t);
    }
    for (Tet nb : block.neighbours) {
      for (auto& n : nb)
        if (n >= 0) n += tet_base;
      mesh.neighbours.push_back(nb);
    }
    mesh.piece.resize(mesh.tets.size(), pieces_[p].index);
    block = Block();  // welded: free it now
  }
  // A cap face is open in the two pieces it separates.
  const std::vector<std::int32_t> touching = tets_touching_caps(mesh, split_.input_vertex_count);
  connect_open_faces(mesh.tets, mesh.neighbours, &touching);
  return mesh;
}

// A piece's band (depth >= 0) and bulk, in piece order each (split_by_depth). The band's Steiner
// points are the ones its tets use, numbered anew in the piece's order (first_steiner_ + their
// rank); the bulk keeps all of them and their ids.
void Welder::split_piece(std::size_t p, const std::vector<std::int8_t>& depth) {
  PieceBand split = split_by_depth(std::move(blocks_[p]), depth, first_steiner_);
  blocks_[p] = std::move(split.band);
  bulks_[p] = std::move(split.bulk);
  band_steiner_[p] = std::move(split.band_steiner);
  band_tets_[p] = std::move(split.band_tets);
  store_bulk(p);
}

void Welder::add_split(PieceBand&& split, BulkStore& owner) {
  const int p = split.index;
  if (p < 0 || static_cast<std::size_t>(p) >= pieces_.size() || pieces_[p].index != p || !split_on_arrival_)
    mismatch(p, "does not match its piece");
  if (blocks_[p].in) mismatch(p, "arrived twice");
  if (split.first_steiner < first_steiner_) mismatch(p, "numbers its Steiner points among the split's points");
  if (split.band_kept && !split.band.tets.empty()) mismatch(p, "came with the band part it keeps");
  note_surface(static_cast<std::size_t>(p));
  move_steiner_ids(split.band.tets, split.first_steiner, first_steiner_);
  bulks_[p] = Block();
  bulks_[p].in = true;
  stored_[p] = {true, static_cast<std::size_t>(split.bulk_tets), static_cast<std::size_t>(split.bulk_steiner_points),
                &owner, split.first_steiner};
  install_band(static_cast<std::size_t>(p), std::move(split));
}

void Welder::note_surface(std::size_t p) {
  referenced_.resize(static_cast<std::size_t>(first_steiner_), false);
  for (std::int32_t v : pieces_[p].global_ids) referenced_[v] = true;
}

void Welder::install_band(std::size_t p, PieceBand&& split) {
  band_elsewhere_[p] = {split.band_kept, static_cast<std::size_t>(split.band_tet_count),
                        std::move(split.band_split_points)};
  blocks_[p] = std::move(split.band);
  blocks_[p].in = true;
  band_steiner_[p] = std::move(split.band_steiner);
  band_tets_[p] = std::move(split.band_tets);
  crossings_[p] = std::move(split.crossings);
  bulk_cap_faces_[p] = std::move(split.cap_faces_outside);
  made_links_[p] = std::move(split.links);
}

void Welder::store_bulk(std::size_t p) {
  Block& bulk = bulks_[p];
  if (!store_ || !store_->put(static_cast<int>(p), bulk)) return;
  stored_[p] = {true, bulk.tets.size(), bulk.steiner_points.size(), store_, first_steiner_};
  bulk = Block();
  bulk.in = true;
}

Welder::Block& Welder::bulk_here(std::size_t p) {
  const StoredBulk stored = stored_[p];
  if (stored.stored) {
    Block bulk = stored.store->take(static_cast<int>(p));
    // A numbered bulk has only its Steiner points that stay (the assembly checks their count).
    if (bulk.tets.size() != stored.tets || (!bulk.numbered && bulk.steiner_points.size() != stored.steiner_points))
      throw InternalError("the bulk of piece " + std::to_string(p) + " came back changed from where it was kept");
    if (!bulk.numbered) move_steiner_ids(bulk.tets, stored.first_steiner, first_steiner_);
    bulk.in = true;
    bulks_[p] = std::move(bulk);
    stored_[p] = StoredBulk();
  }
  return bulks_[p];
}

std::size_t Welder::bulk_tets(std::size_t p) const {
  return stored_[p].stored ? stored_[p].tets : bulks_[p].tets.size();
}

std::size_t Welder::bulk_steiner_points(std::size_t p) const {
  return stored_[p].stored ? stored_[p].steiner_points : bulks_[p].steiner_points.size();
}

void Welder::band_here(std::size_t p) {
  BandElsewhere& elsewhere = band_elsewhere_[p];
  if (!elsewhere.kept) return;
  const StoredBulk& stored = stored_[p];
  if (!stored.stored) mismatch(static_cast<int>(p), "has a band part kept where no bulk is");
  PieceBand part = stored.store->take_band(static_cast<int>(p));
  if (part.index != static_cast<int>(p) || part.band.tets.size() != elsewhere.tets ||
      part.band.neighbours.size() != elsewhere.tets || part.band_tets.size() != elsewhere.tets)
    mismatch(static_cast<int>(p), "came back from where its band part was kept with another band");
  move_steiner_ids(part.band.tets, stored.first_steiner, first_steiner_);
  blocks_[p].tets = std::move(part.band.tets);
  blocks_[p].neighbours = std::move(part.band.neighbours);
  band_tets_[p] = std::move(part.band_tets);
  elsewhere = BandElsewhere();
}

std::size_t Welder::band_part_tets(std::size_t p) const {
  return band_elsewhere_[p].kept ? band_elsewhere_[p].tets : blocks_[p].tets.size();
}

void Welder::rejoin(std::size_t p) {
  band_here(p);
  Block& bulk = bulk_here(p);
  blocks_[p] =
      join_band_and_bulk(std::move(blocks_[p]), std::move(bulk), band_steiner_[p], band_tets_[p], first_steiner_);
  bulk = Block();
  std::vector<std::int32_t>().swap(band_steiner_[p]);
  std::vector<std::int32_t>().swap(band_tets_[p]);
  made_links_[p].reset();
}

TetMesh Welder::finish_band(std::vector<Point3> split_points, BandSpec spec) {
  split_bands(spec);
  return weld_bands(std::move(split_points));
}

void Welder::split_bands(BandSpec spec) {
  for (std::size_t p = 0; p < blocks_.size(); ++p)
    if (!blocks_[p].in) mismatch(static_cast<int>(p), "is missing");
  spec.split_point_count = first_steiner_;
  if (split_on_arrival_ &&
      (spec.layers != split_on_arrival_->layers || spec.first_removed != split_on_arrival_->first_removed ||
       spec.end_removed != split_on_arrival_->end_removed))
    throw InternalError("the pieces were split on arrival for other bands");
  if (all_split()) {
    take_crossings();
  } else {
    for (std::size_t p = 0; p < blocks_.size(); ++p)
      if (bulks_[p].in) rejoin(p);
    std::vector<const std::vector<Tet>*> tets, neighbours;
    for (const Block& block : blocks_) tets.push_back(&block.tets), neighbours.push_back(&block.neighbours);
    std::vector<std::vector<std::int8_t>> depths = mark_bands(tets, neighbours, spec);
    for (std::size_t p = 0; p < blocks_.size(); ++p) {
      split_piece(p, depths[p]);
      std::vector<std::int8_t>().swap(depths[p]);
    }
  }
  band_tets_.assign(blocks_.size(), {});  // no piece goes back now (8 MB at 22.1M input faces)
  band_links_.clear();
  for (std::size_t p = 0; p < blocks_.size(); ++p) {
    band_links_.push_back(made_links_[p] ? std::move(*made_links_[p]) : band_part_links(blocks_[p], spec));
    made_links_[p].reset();
  }
}

std::size_t Welder::band_tet_count() const {
  std::size_t tets = 0;
  for (std::size_t p = 0; p < blocks_.size(); ++p) tets += band_part_tets(p);
  return tets;
}

std::vector<BandPartPlace> Welder::band_part_places() const {
  std::vector<BandPartPlace> places;
  std::int32_t tets = 0, steiner_points = 0;
  for (std::size_t p = 0; p < blocks_.size(); ++p) {
    places.push_back({pieces_[p].index, tets, first_steiner_, first_steiner_ + steiner_points});
    tets += static_cast<std::int32_t>(band_part_tets(p));
    steiner_points += static_cast<std::int32_t>(blocks_[p].steiner_points.size());
  }
  return places;
}

void Welder::cut_kept_shares(const std::vector<std::vector<int>>& chain_of_part, const std::vector<int>& order,
                             const std::vector<int>& healers) {
  const std::vector<BandPartPlace> places = band_part_places();
  std::map<BulkStore*, std::vector<BandPartPlan>> plans;
  for (std::size_t p = 0; p < blocks_.size(); ++p) {
    if (!band_elsewhere_[p].kept) continue;
    BandPartPlan plan{places[p], chain_of_part.at(p)};
    plan.place.steiner_from = stored_[p].first_steiner;  // in the store's ids
    plans[stored_[p].store].push_back(std::move(plan));
  }
  share_stores_.clear();
  for (auto& [store, kept] : plans) {
    store->cut_shares(kept, order, healers);
    share_stores_.push_back(store);
  }
}

std::vector<ChainShare> Welder::kept_shares(int chain) {
  std::vector<ChainShare> shares;
  for (BulkStore* store : share_stores_)
    for (ChainShare& share : store->shares(chain)) {
      const int p = share.piece;
      if (share.chain != chain || p < 0 || static_cast<std::size_t>(p) >= blocks_.size() || !band_elsewhere_[p].kept ||
          stored_[p].store != store)
        mismatch(p, "'s band part gave a share of another chain or piece");
      shares.push_back(std::move(share));
    }
  return shares;
}

std::vector<std::int32_t> Welder::band_split_points(const std::vector<std::size_t>& pieces) const {
  std::vector<std::vector<std::int32_t>> here;  // (those kept elsewhere came with the parts' links)
  std::vector<const std::vector<std::int32_t>*> parts;
  here.reserve(pieces.size());
  for (const std::size_t p : pieces)
    if (band_elsewhere_.at(p).kept) {
      parts.push_back(&band_elsewhere_[p].split_points);
    } else {
      here.push_back(split_points_of(blocks_[p].tets, first_steiner_));
      parts.push_back(&here.back());
    }
  return merged_split_points(parts);
}

void Welder::reserve_for_assembly(std::vector<Point3>& split_points) const {
  if (!all_split()) throw InternalError("the welder welds the bands only after split_bands");
  std::size_t steiner_total = 0;
  for (std::size_t p = 0; p < blocks_.size(); ++p) steiner_total += bulk_steiner_points(p);
  // Room for every piece's Steiner points, which the assembly adds: growing the array then would
  // copy every point while the old array still exists (270 MB at 22.1M input faces).
  reserve_with_room(split_points, split_points.size() + steiner_total);
}

TetMesh Welder::weld_bands(std::vector<Point3> split_points) {
  for (std::size_t p = 0; p < blocks_.size(); ++p) band_here(p);
  reserve_for_assembly(split_points);
  TetMesh band = weld_blocks(std::move(split_points), blocks_);
  band_used_before_ = used_vertices<bool>(band.points.size(), band.tets);
  return band;
}

TetMesh Welder::band_points(std::vector<Point3> split_points) {
  reserve_for_assembly(split_points);
  TetMesh band;
  band.points = std::move(split_points);
  const std::vector<BandPartPlace> places = band_part_places();
  for (std::size_t p = 0; p < blocks_.size(); ++p)
    band.points.insert(band.points.end(), blocks_[p].steiner_points.begin(), blocks_[p].steiner_points.end());
  band_used_before_.assign(band.points.size(), false);
  for (std::size_t p = 0; p < blocks_.size(); ++p) {
    if (band_elsewhere_[p].kept) {  // (every Steiner point of a band part is one its tets use)
      for (const std::int32_t v : band_elsewhere_[p].split_points) band_used_before_[v] = true;
      std::fill_n(band_used_before_.begin() + places[p].steiner_to, blocks_[p].steiner_points.size(), true);
    }
    for (const Tet& tet : blocks_[p].tets)
      for (const std::int32_t v : tet)
        band_used_before_[v >= places[p].steiner_from ? v - places[p].steiner_from + places[p].steiner_to : v] = true;
    blocks_[p] = Block();
  }
  return band;
}

bool Welder::all_split() const {
  return std::all_of(bulks_.begin(), bulks_.end(), [](const Block& b) { return b.in; });
}

std::size_t Welder::bulk_tet_count() const {
  std::size_t count = 0;
  for (std::size_t p = 0; p < bulks_.size(); ++p) count += bulk_tets(p);
  return count;
}

AssemblyPoints Welder::assembly_points() {
  AssemblyPoints points;
  points.split_points = first_steiner_;
  for (std::size_t p = 0; p < bulks_.size(); ++p)
    points.steiner_counts.push_back(static_cast<std::int64_t>(bulk_steiner_points(p)));
  points.band_steiner = std::move(band_steiner_);
  points.band_used_before = std::move(band_used_before_);
  points.referenced = std::move(referenced_);
  return points;
}

void Welder::number_bulks(const std::vector<BulkNumbering>& shares) {
  std::map<BulkStore*, std::vector<BulkShare>> elsewhere;
  for (std::size_t p = 0; p < stored_.size(); ++p)
    if (stored_[p].stored)
      elsewhere[stored_[p].store].push_back({static_cast<std::int32_t>(p), stored_[p].first_steiner, shares[p]});
  for (auto& [store, kept] : elsewhere) store->number(kept);
  for (std::size_t p = 0; p < stored_.size(); ++p)
    if (!stored_[p].stored) number_bulk(bulks_[p], shares[p], first_steiner_);
}

AssemblyNumbering Welder::numbering(const TetMesh& healed_band, bool drop_unused,
                                    const std::vector<std::int32_t>& used_elsewhere) {
  if (!all_split()) throw InternalError("the welder assembles only after finish_band");
  return AssemblyNumbering(assembly_points(), healed_band, drop_unused, used_elsewhere);
}

TetMesh Welder::assemble(TetMesh&& healed_band, bool drop_unused) {
  const AssemblyNumbering numbers = numbering(healed_band, drop_unused);
  return assemble(std::move(healed_band), numbers);
}

TetMesh Welder::assemble(TetMesh&& healed_band, const AssemblyNumbering& numbering) {
  const std::size_t k = bulks_.size();
  if (!all_split()) throw InternalError("the welder assembles only after finish_band");
  std::size_t tet_total = healed_band.tets.size();
  for (std::size_t p = 0; p < k; ++p) tet_total += bulk_tets(p);
  check_int32_sizes(tet_total, static_cast<std::size_t>(numbering.point_count()));
  TetMesh mesh;
  // 1. Points: the split surface's and those healing added, from the band (in place: a point only
  // moves down); every piece's Steiner points with its bulk, below (a stored bulk comes back once).
  mesh.points = std::move(healed_band.points);
  const std::int64_t healing_band = numbering.healing_first_band();
  const std::int64_t healing_welded = numbering.healing_first_welded();
  std::vector<Point3> healing_points;
  numbering.for_each_kept(healing_welded, numbering.welded_count(), [&](std::int64_t w, std::int64_t) {
    healing_points.push_back(mesh.points[static_cast<std::size_t>(healing_band + (w - healing_welded))]);
  });
  numbering.for_each_kept(0, first_steiner_,
                          [&](std::int64_t v, std::int64_t to) { mesh.points[to] = mesh.points[v]; });
  mesh.points.resize(static_cast<std::size_t>(numbering.point_count()));
  std::copy(healing_points.begin(), healing_points.end(),
            mesh.points.end() - static_cast<std::ptrdiff_t>(healing_points.size()));
  reserve_with_room(mesh.points, mesh.points.size());
  auto renumbered = [](Tet t, const auto& to) {  // ids fit: checked above
    for (auto& v : t)
      if ((v = static_cast<std::int32_t>(to(v))) < 0) throw InternalError("a point the assembly dropped is still used");
    return t;
  };
  // 2. Tets: the bulks in piece order, then the band; the faces of the bulks' rims, and the tets
  // with a face that may lie on a cap (three vertices on the planes).
  reserve_with_room(mesh.tets, tet_total);
  reserve_with_room(mesh.neighbours, tet_total);
  reserve_with_room(mesh.piece, tet_total);
  std::vector<RimFace> rim;
  std::vector<std::int32_t> on_caps;
  std::vector<BulkNumbering> shares;
  for (std::size_t p = 0; p < k; ++p) shares.push_back(numbering.for_bulk(p));
  number_bulks(shares);
  for (std::size_t p = 0; p < k; ++p) {
    const bool kept_elsewhere = stored_[p].stored;
    const std::size_t steiner_points = bulk_steiner_points(p);
    Block& bulk = bulk_here(p);
    const BulkNumbering& number = shares[p];
    number_bulk(bulk, number, first_steiner_);  // unless its store did
    if (kept_elsewhere && bulk.steiner_points.size() + number.dropped_steiner.size() != steiner_points)
      throw InternalError("the bulk of piece " + std::to_string(p) + " came back with other Steiner points");
    std::copy(bulk.steiner_points.begin(), bulk.steiner_points.end(), mesh.points.begin() + number.first_steiner);
    // Numbered, the input's vertices are still the first ids (fewer when some go).
    const std::int32_t input_vertices = number.split_kept_below(split_.input_vertex_count);
    const auto base = static_cast<std::int32_t>(mesh.tets.size());
    for (const Tet& compact : bulk.tets) {
      const Tet t = renumbered(compact, bulk.ids);
      if (may_touch_cap(t, input_vertices)) on_caps.push_back(static_cast<std::int32_t>(mesh.tets.size()));
      mesh.tets.push_back(t);
    }
    for (Tet nb : bulk.neighbours) {
      for (auto& n : nb)
        if (n >= 0) n += base;
      mesh.neighbours.push_back(nb);
    }
    for (auto slot : bulk.rim) {
      const std::uint64_t global = slot + 4 * static_cast<std::uint64_t>(base);
      rim.push_back({FaceKey(outward_face(mesh.tets[global / 4], static_cast<int>(global % 4))), global});
    }
    mesh.piece.resize(mesh.tets.size(), pieces_[p].index);
    bulk = Block();
  }
  const auto band_base = static_cast<std::int32_t>(mesh.tets.size());
  for (std::size_t t = 0; t < healed_band.tets.size(); ++t) {
    const Tet& tet = healed_band.tets[t];
    if (may_touch_cap(tet, split_.input_vertex_count)) on_caps.push_back(static_cast<std::int32_t>(mesh.tets.size()));
    mesh.tets.push_back(renumbered(tet, [&](std::int32_t v) { return numbering.of_band(v); }));
    Tet nb = healed_band.neighbours[t];
    for (auto& n : nb)
      if (n >= 0) n += band_base;
    mesh.neighbours.push_back(nb);
    mesh.piece.push_back(healed_band.piece.empty() ? -1 : healed_band.piece[t]);
  }
  healed_band = TetMesh();
  blocks_.assign(k, Block());
  band_elsewhere_.assign(k, {});
  bulks_.assign(k, Block());
  band_steiner_.assign(k, {});
  band_tets_.assign(k, {});
  // 3. Each bulk's rim to the band (healing left those faces as they were), then across the caps.
  join_rim(mesh, band_base, std::move(rim));
  connect_open_faces(mesh.tets, mesh.neighbours, &on_caps);
  return mesh;
}

bool Welder::keeps_bulks_elsewhere() const {
  return std::any_of(stored_.begin(), stored_.end(),
                     [this](const StoredBulk& s) { return s.stored && s.store != store_; });
}

namespace {

// A spread mesh's rows rank 0 writes itself: the split surface's points that stay, and those
// healing added (the last rows).
void spread_points(const AssemblyNumbering& numbering, std::int32_t split_points, const TetMesh& healed_band,
                   SpreadMesh& mesh) {
  numbering.for_each_kept(0, split_points,
                          [&](std::int64_t v, std::int64_t) { mesh.split_points.push_back(healed_band.points[v]); });
  const std::int64_t healing_band = numbering.healing_first_band(), healing_welded = numbering.healing_first_welded();
  mesh.first_healing_point = mesh.points;
  numbering.for_each_kept(healing_welded, numbering.welded_count(), [&](std::int64_t w, std::int64_t to) {
    mesh.first_healing_point = std::min(mesh.first_healing_point, to);
    mesh.healing_points.push_back(healed_band.points[static_cast<std::size_t>(healing_band + (w - healing_welded))]);
  });
}

// The band as blocks: one per healed chain, or the whole band as one.
struct BandBlocks {
  std::vector<BlockLinks> links;         // per block
  std::vector<std::int32_t> first_tet;   // per block, its first row in the band; and one past the last
  std::vector<std::int32_t> first_here;  // per block, its first tet here (in label); and one past the last
  std::vector<char> here;                // per block: whether its tets are here (else on the rank that healed it)
  std::vector<std::int32_t> label;       // per band tet here: its component in its block
};

// The band's links when it came as healed chains: each chain's, keys moved to the mesh's ids
// (through the band's own, which keep the order: each chain's keys stay sorted). When a chain is
// kept by the rank that healed it, every chain's rows go into mesh.band_runs, and those kept
// elsewhere get the mesh's ids of their points.
BandBlocks chain_blocks(const AssemblyNumbering& numbering, SpreadMesh& mesh, std::vector<BandChainLinks>&& chains) {
  auto mesh_id = [&](std::int64_t v) {
    const std::int64_t id = numbering.of_band(static_cast<std::int32_t>(v));
    if (id < 0) throw InternalError("an open face of a healed chain has a point the assembly dropped");
    return id;
  };
  const bool runs = std::any_of(chains.begin(), chains.end(), [](const BandChainLinks& c) { return c.kept_on >= 0; });
  BandBlocks blocks;
  std::int32_t row = 0;
  for (std::size_t c = 0; c < chains.size(); ++c) {
    BandChainLinks& chain = chains[c];
    const bool here = chain.kept_on < 0;
    if (chain.first_tet != row || (here && static_cast<std::int32_t>(chain.label.size()) != chain.tets))
      throw InternalError("the healed chains' links do not match the band");
    for (auto& key : chain.links.keys)
      for (auto& v : key) v = mesh_id(v);
    blocks.links.push_back(std::move(chain.links));
    blocks.first_tet.push_back(row);
    blocks.first_here.push_back(static_cast<std::int32_t>(blocks.label.size()));
    blocks.here.push_back(here);
    if (runs) {
      BandRun& run = mesh.band_runs.emplace_back();
      run.chain = here ? static_cast<int>(c) : chain.kept_as, run.rank = here ? 0 : chain.kept_on;
      run.first_row = mesh.first_band_tet + row, run.tets = chain.tets;
      run.first_here = static_cast<std::int64_t>(blocks.label.size());
      for (const std::int32_t v : chain.band_ids) run.point_ids.push_back(v < 0 ? -1 : numbering.of_band(v));
    }
    blocks.label.insert(blocks.label.end(), chain.label.begin(), chain.label.end());
    row += chain.tets;
  }
  if (blocks.label.size() != mesh.band_tets.size())
    throw InternalError("the healed chains' links do not match the band");
  blocks.first_tet.push_back(row);
  blocks.first_here.push_back(static_cast<std::int32_t>(blocks.label.size()));
  return blocks;
}

// The healed band, its rows after every bulk's, in compact ids (SpreadMesh::band_ids), with the
// pieces' Steiner points it uses; its links (all its open faces): the chains' (chains, when the
// band is made of them) or found here. Band ids from split_points on (the pieces' band Steiner
// points in piece order, then healing's) go to the mesh's ids in order.
BandBlocks spread_band(const AssemblyNumbering& numbering, std::int32_t split_points, TetMesh&& healed_band,
                       std::vector<BandChainLinks>&& chains, SpreadMesh& mesh) {
  const auto split_kept = static_cast<std::int64_t>(mesh.split_points.size());
  // 1. The points past the split surface's that the tets use: the table of the compact ids.
  std::vector<std::int32_t> compact(healed_band.points.size() - static_cast<std::size_t>(split_points), -1);
  for (const Tet& t : healed_band.tets)
    for (std::int32_t v : t)
      if (v >= split_points) compact[v - split_points] = 0;
  for (std::size_t b = 0; b < compact.size(); ++b) {
    if (compact[b] < 0) continue;
    const std::int64_t id = numbering.of_band(split_points + static_cast<std::int32_t>(b));
    if (id < 0 || (!mesh.band_point_ids.empty() && id <= mesh.band_point_ids.back()))
      throw InternalError("a band point past the split surface's is dropped or out of order");
    compact[b] = static_cast<std::int32_t>(split_kept + static_cast<std::int64_t>(mesh.band_point_ids.size()));
    mesh.band_point_ids.push_back(id);
    if (id < mesh.first_healing_point)  // a piece's Steiner point: its row is its bulk's
      mesh.band_steiner_points.push_back(healed_band.points[split_points + b]);
  }
  // 2. The tets in compact ids.
  mesh.band_tets.reserve(healed_band.tets.size());
  for (Tet t : healed_band.tets) {
    for (auto& v : t) {
      if (v >= split_points) {
        v = compact[v - split_points];
      } else if ((v = static_cast<std::int32_t>(numbering.of_band(v))) < 0) {
        throw InternalError("a point the assembly dropped is still used");
      }
    }
    mesh.band_tets.push_back(t);
  }
  mesh.band_piece =
      healed_band.piece.empty() ? std::vector<std::int32_t>(healed_band.tets.size(), -1) : std::move(healed_band.piece);
  // 3. Its links.
  BandBlocks blocks;
  if (!chains.empty()) {
    blocks = chain_blocks(numbering, mesh, std::move(chains));
  } else {
    blocks.links.push_back(
        block_links(mesh.band_tets, mesh.band_ids(), healed_band.neighbours, true, 0, {}, blocks.label));
    blocks.first_tet = {0, static_cast<std::int32_t>(mesh.band_tets.size())};
    blocks.first_here = blocks.first_tet;
    blocks.here = {1};
  }
  mesh.band_neighbours = std::move(healed_band.neighbours);
  healed_band = TetMesh();
  return blocks;
}

}  // namespace

std::vector<BlockLinks> Welder::spread_bulks(const AssemblyNumbering& numbering, SpreadMesh& mesh, StepClock& clock) {
  const std::size_t k = bulks_.size();
  // This process's own store (scratch files) gives its bulks back: the writers take them here.
  for (std::size_t p = 0; p < k; ++p)
    if (stored_[p].stored && stored_[p].store == store_) bulk_here(p);
  std::vector<BulkNumbering> shares;
  std::vector<std::size_t> steiner_points;  // each piece's, before the numbering drops some
  for (std::size_t p = 0; p < k; ++p)
    shares.push_back(numbering.for_bulk(p)), steiner_points.push_back(bulk_steiner_points(p));
  number_bulks(shares);
  const std::int32_t input_vertices = k == 0 ? 0 : shares[0].split_kept_below(split_.input_vertex_count);
  std::vector<BlockLinks> links(k);
  for (BulkStore* store : bulk_stores()) store->ask_links(input_vertices);  // made there while rank 0 goes on
  std::int64_t row = 0;
  for (std::size_t p = 0; p < k; ++p) {
    SpreadBulk& bulk = mesh.bulks.emplace_back();
    bulk.piece = pieces_[p].index;
    bulk.first_point = shares[p].first_steiner;
    bulk.points = static_cast<std::int64_t>(steiner_points[p] - shares[p].dropped_steiner.size());
    bulk.first_tet = row;
    bulk.tets = static_cast<std::int64_t>(bulk_tets(p));
    row += bulk.tets;
    if (stored_[p].stored) continue;
    bulk.here = true;
    bulk.block = std::move(bulks_[p]);
    std::vector<std::int32_t> label;
    links[p] = block_links(bulk.block.tets, bulk.block.ids, bulk.block.neighbours, false, input_vertices,
                           bulk.block.rim, label);
  }
  clock.lap("own bulks");
  mesh.first_band_tet = row;
  return links;
}

std::set<BulkStore*> Welder::bulk_stores() const {
  std::set<BulkStore*> stores;
  for (const StoredBulk& bulk : stored_)
    if (bulk.stored) stores.insert(bulk.store);
  return stores;
}

void Welder::take_bulk_links(std::vector<BlockLinks>& links) {
  const std::size_t k = bulks_.size();
  std::vector<char> linked;  // those kept here are linked already
  for (const StoredBulk& bulk : stored_) linked.push_back(!bulk.stored);
  for (BulkStore* store : bulk_stores())
    for (auto& [piece, found] : store->links()) {
      if (piece < 0 || static_cast<std::size_t>(piece) >= k || !stored_[piece].stored)
        throw InternalError("links of a bulk no store keeps (piece " + std::to_string(piece) + ")");
      links[piece] = std::move(found);
      linked[piece] = 1;
    }
  for (std::size_t p = 0; p < k; ++p)
    if (!linked[p]) throw InternalError("the rank keeping the bulk of piece " + std::to_string(p) + " did not link it");
}

SpreadMesh Welder::spread(TetMesh&& healed_band, bool faces_across, std::vector<BandChainLinks>&& chains) {
  const std::size_t k = bulks_.size();
  if (!all_split()) throw InternalError("the welder spreads the mesh only after finish_band");
  StepClock clock;
  std::vector<std::int32_t> used_elsewhere;  // (by the healed chains kept where they healed)
  std::int64_t tets_elsewhere = 0;
  for (const BandChainLinks& chain : chains) {
    if (chain.kept_on < 0) continue;
    if (faces_across) throw InternalError("the tets across a healed chain kept elsewhere were asked for");
    tets_elsewhere += chain.tets;
    for (const std::int32_t v : chain.band_ids)
      if (v >= 0) used_elsewhere.push_back(v);
  }
  const AssemblyNumbering numbering = this->numbering(healed_band, true, used_elsewhere);
  used_elsewhere = {};
  clock.lap("numbering");
  SpreadMesh mesh;
  mesh.points = numbering.point_count();
  mesh.tets = static_cast<std::int64_t>(healed_band.tets.size() + bulk_tet_count()) + tets_elsewhere;
  // 1. The bulks, numbered where they are, in piece order, and the links of those kept here. The
  //    ranks keeping the others make theirs meanwhile, while steps 2 and 3 run here.
  std::vector<BlockLinks> links = spread_bulks(numbering, mesh, clock);
  // 2. Rank 0's points.
  spread_points(numbering, first_steiner_, healed_band, mesh);
  clock.lap("points");
  // 3. The healed band, last, and its links: a block per healed chain, or one.
  BandBlocks band = spread_band(numbering, first_steiner_, std::move(healed_band), std::move(chains), mesh);
  const std::size_t band_blocks = band.links.size();
  for (BlockLinks& block : band.links) links.push_back(std::move(block));
  clock.lap("band");
  // 4. The links of the bulks kept elsewhere.
  take_bulk_links(links);
  clock.lap("other bulks");
  // 5. The connected solids, across the blocks' shared faces.
  std::vector<std::int64_t> first_row;
  for (const SpreadBulk& bulk : mesh.bulks) first_row.push_back(bulk.first_tet);
  for (std::size_t b = 0; b < band_blocks; ++b) first_row.push_back(mesh.first_band_tet + band.first_tet[b]);
  const std::vector<std::vector<std::int32_t>> solids = solids_of_blocks(links, first_row);
  for (std::size_t p = 0; p < k; ++p) mesh.bulks[p].solid = solids[p];
  mesh.band_solid.reserve(band.label.size());
  for (std::size_t b = 0; b < band_blocks; ++b) {
    if (!band.here[b]) {
      mesh.band_runs[b].solid = solids[k + b];
      continue;
    }
    for (std::int32_t t = band.first_here[b]; t < band.first_here[b + 1]; ++t)
      mesh.band_solid.push_back(solids[k + b][band.label[t]]);
  }
  clock.lap("solids");
  // 6. The tets across the blocks' shared faces (the neighbours a TetGen .neigh file names).
  if (faces_across) {
    std::vector<std::vector<FaceAcross>> across = faces_across_blocks(links, first_row);
    for (std::size_t p = 0; p < k; ++p) mesh.bulks[p].across = std::move(across[p]);
    for (std::size_t b = 0; b < band_blocks; ++b)  // (each block's faces ascending, the blocks in order)
      for (FaceAcross face : across[k + b]) {
        face.face += 4 * static_cast<std::uint64_t>(band.first_here[b]);
        mesh.band_across.push_back(face);
      }
    mesh.has_across = true;
    clock.lap("across");
  }
  log::debug("spreading the mesh: " + clock.steps);
  blocks_.assign(k, Block());
  band_elsewhere_.assign(k, {});
  bulks_.assign(k, Block());
  band_steiner_.assign(k, {});
  band_tets_.assign(k, {});
  return mesh;
}

std::vector<std::pair<int, HealedChain>> Welder::take_kept_chains() {
  std::vector<std::pair<int, HealedChain>> chains;
  for (BulkStore* store : bulk_stores())
    for (auto& chain : store->take_chains()) chains.push_back(std::move(chain));
  return chains;
}

TetMesh weld(const SplitSurface& split, const std::vector<PieceSurface>& pieces, std::vector<PieceTetMesh>&& results) {
  Welder welder(split, pieces);
  for (auto& result : results) welder.add(std::move(result));
  return welder.finish(split.points);
}

}  // namespace partet
