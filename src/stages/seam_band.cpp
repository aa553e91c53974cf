#include "stages/seam_band.hpp"

#include <algorithm>
#include <string>

#include "partet/errors.hpp"
#include "stages/seam_chains.hpp"

namespace partet {

BandMarks::BandMarks(const std::vector<Tet>& tets, const std::vector<Tet>& neighbours, const BandSpec& spec)
    : neighbours_(neighbours), layers_(spec.layers), depth_(tets.size(), -1) {
  if (spec.layers < 0 || spec.layers > 100)
    throw InternalError("a seam band of " + std::to_string(spec.layers) + " layers");
  std::vector<std::int32_t> seeds;
  for (std::size_t t = 0; t < tets.size(); ++t) {
    const Tet& tet = tets[t];
    if (spec.removes(tet[0]) || spec.removes(tet[1]) || spec.removes(tet[2]) || spec.removes(tet[3])) {
      depth_[t] = 0;
      seeds.push_back(static_cast<std::int32_t>(t));
    }
    for (int j = 0; j < 4; ++j) {
      if (neighbours[t][j] >= 0) continue;
      const Triangle face = outward_face(tet, j);
      if (spec.on_planes(face[0]) && spec.on_planes(face[1]) && spec.on_planes(face[2]))
        cap_faces_.push_back({FaceKey(face), static_cast<std::int32_t>(t)});
    }
  }
  std::sort(cap_faces_.begin(), cap_faces_.end());
  spread(std::move(seeds));
}

// Breadth first from `from` (their depths set), lowering depths where a shorter way is found.
void BandMarks::spread(std::vector<std::int32_t> from) {
  for (std::size_t i = 0; i < from.size(); ++i) {
    const std::int32_t t = from[i];
    const int next = depth_[t] + 1;
    if (next > layers_) continue;
    for (auto nb : neighbours_[t])
      if (nb >= 0 && (depth_[nb] < 0 || depth_[nb] > next)) {
        depth_[nb] = static_cast<std::int8_t>(next);
        from.push_back(nb);
      }
  }
}

std::vector<CapCrossing> BandMarks::crossings() const {
  std::vector<CapCrossing> out;
  for (const auto& face : cap_faces_) {
    const int d = depth_[face.tet];
    if (d >= 0 && d < layers_) out.push_back({face.key, d});
  }
  return out;
}

std::vector<FaceKey> BandMarks::cap_faces_outside() const {
  std::vector<FaceKey> out;
  for (const auto& face : cap_faces_)
    if (depth_[face.tet] < 0) out.push_back(face.key);
  return out;
}

bool BandMarks::enter(const std::vector<CapCrossing>& from_neighbour) {
  std::vector<std::int32_t> entered;
  for (const auto& crossing : from_neighbour) {
    const OpenCapFace probe{crossing.key, 0};
    const auto it = std::lower_bound(cap_faces_.begin(), cap_faces_.end(), probe);
    if (it == cap_faces_.end() || !(it->key == crossing.key)) continue;  // on the neighbour's other cap
    const int d = crossing.depth + 1;
    if (d > layers_ || (depth_[it->tet] >= 0 && depth_[it->tet] <= d)) continue;
    depth_[it->tet] = static_cast<std::int8_t>(d);
    entered.push_back(it->tet);
  }
  const bool grew = !entered.empty();
  spread(std::move(entered));
  return grew;
}

TetBlock in_global_ids(PieceTetMesh&& result, const std::vector<std::int32_t>& global_ids, std::int32_t first_steiner) {
  TetBlock block;
  const std::int32_t surface_count = result.surface_point_count;
  block.tets = std::move(result.mesh.tets);
  for (Tet& t : block.tets)
    for (auto& v : t) v = v < surface_count ? global_ids[v] : first_steiner + (v - surface_count);
  block.neighbours = std::move(result.mesh.neighbours);
  block.steiner_points = std::move(result.mesh.steiner_points);
  block.in = true;
  result.mesh = LocalTetMesh();
  return block;
}

PieceBand split_by_depth(TetBlock&& whole, const std::vector<std::int8_t>& depth, std::int32_t first_steiner) {
  if (depth.size() != whole.tets.size()) throw InternalError("a piece's band marks do not match its tets");
  PieceBand split;
  split.first_steiner = first_steiner;
  std::vector<std::int32_t>& band_steiner = split.band_steiner;
  std::vector<std::int32_t>& band_tets = split.band_tets;
  std::vector<std::int32_t> side_id(whole.tets.size());
  std::int32_t in_bulk = 0;
  for (std::size_t t = 0; t < depth.size(); ++t)
    if (depth[t] >= 0) {
      side_id[t] = static_cast<std::int32_t>(band_tets.size());
      band_tets.push_back(static_cast<std::int32_t>(t));
    } else {
      side_id[t] = in_bulk++;
    }
  TetBlock& band = split.band;
  TetBlock& bulk = split.bulk;
  band.in = bulk.in = true;
  std::vector<std::int32_t> band_id(whole.steiner_points.size(), -1);
  for (auto t : band_tets)
    for (auto v : whole.tets[t])
      if (v >= first_steiner) band_id[v - first_steiner] = 0;
  for (std::size_t s = 0; s < band_id.size(); ++s)
    if (band_id[s] == 0) {
      band_id[s] = static_cast<std::int32_t>(band_steiner.size());
      band_steiner.push_back(static_cast<std::int32_t>(s));
      band.steiner_points.push_back(whole.steiner_points[s]);
    }
  band.tets.reserve(band_tets.size());
  band.neighbours.reserve(band_tets.size());
  bulk.tets.reserve(static_cast<std::size_t>(in_bulk));
  bulk.neighbours.reserve(static_cast<std::size_t>(in_bulk));
  for (std::size_t t = 0; t < depth.size(); ++t) {
    const bool banded = depth[t] >= 0;
    Tet nbs = whole.neighbours[t];
    for (int j = 0; j < 4; ++j) {
      auto& nb = nbs[j];
      if (nb < 0) continue;
      const bool same_side = (depth[nb] >= 0) == banded;
      if (!same_side && !banded) bulk.rim.push_back(4 * static_cast<std::uint64_t>(side_id[t]) + j);
      nb = same_side ? side_id[nb] : -1;
    }
    Tet tet = whole.tets[t];
    if (banded) {
      for (auto& v : tet)
        if (v >= first_steiner) v = first_steiner + band_id[v - first_steiner];
      band.tets.push_back(tet);
      band.neighbours.push_back(nbs);
    } else {
      bulk.tets.push_back(tet);
      bulk.neighbours.push_back(nbs);
    }
  }
  bulk.steiner_points = std::move(whole.steiner_points);
  whole = TetBlock();
  split.bulk_tets = static_cast<std::int64_t>(bulk.tets.size());
  split.bulk_steiner_points = static_cast<std::int64_t>(bulk.steiner_points.size());
  return split;
}

PieceBand split_where_meshed(PieceTetMesh&& result, const std::vector<std::int32_t>& global_ids, const BandSpec& spec) {
  if (spec.layers != 1) throw InternalError("a piece is split where it was meshed only for one layer");
  if (result.surface_point_count != static_cast<std::int32_t>(global_ids.size()))
    throw InternalError("the result of piece " + std::to_string(result.index) + " does not match its piece");
  const int index = result.index;
  PieceBand split = split_alone(in_global_ids(std::move(result), global_ids, spec.split_point_count), spec);
  split.index = index;
  return split;
}

PieceBand split_alone(TetBlock&& whole, const BandSpec& spec) {
  BandMarks marks(whole.tets, whole.neighbours, spec);
  std::vector<CapCrossing> crossings = marks.crossings();
  std::vector<FaceKey> outside = marks.cap_faces_outside();
  PieceBand split = split_by_depth(std::move(whole), marks.take_depth(), spec.split_point_count);
  split.crossings = std::move(crossings);
  split.cap_faces_outside = std::move(outside);
  split.links = band_part_links(split.band, spec);
  return split;
}

TetBlock join_band_and_bulk(TetBlock&& band, TetBlock&& bulk, const std::vector<std::int32_t>& band_steiner,
                            const std::vector<std::int32_t>& band_tets, std::int32_t first_steiner) {
  const std::size_t count = band.tets.size() + bulk.tets.size();
  // Where each bulk tet was: the places the band's tets did not take, in order.
  std::vector<std::int32_t> bulk_tets;
  bulk_tets.reserve(bulk.tets.size());
  for (std::size_t t = 0, next_band = 0; t < count; ++t)
    if (next_band < band_tets.size() && band_tets[next_band] == static_cast<std::int32_t>(t))
      ++next_band;
    else
      bulk_tets.push_back(static_cast<std::int32_t>(t));
  TetBlock whole;
  whole.in = true;
  whole.tets.resize(count);
  whole.neighbours.resize(count);
  auto place = [&](const TetBlock& side, const std::vector<std::int32_t>& at, bool banded) {
    for (std::size_t i = 0; i < side.tets.size(); ++i) {
      Tet tet = side.tets[i];
      if (banded)
        for (auto& v : tet)
          if (v >= first_steiner) v = first_steiner + band_steiner[v - first_steiner];
      Tet nbs = side.neighbours[i];
      for (auto& nb : nbs)
        if (nb >= 0) nb = at[nb];
      whole.tets[at[i]] = tet;
      whole.neighbours[at[i]] = nbs;
    }
  };
  place(band, band_tets, true);
  place(bulk, bulk_tets, false);
  // The faces between band and bulk (open on both sides): the band's tets and the rim's.
  std::vector<std::int32_t> across = band_tets;
  for (auto slot : bulk.rim) across.push_back(bulk_tets[slot / 4]);
  std::sort(across.begin(), across.end());
  across.erase(std::unique(across.begin(), across.end()), across.end());
  connect_open_faces(whole.tets, whole.neighbours, &across);
  whole.steiner_points = std::move(bulk.steiner_points);
  band = TetBlock();
  bulk = TetBlock();
  return whole;
}

PieceBand grow_band(BandToGrow&& band, TetBlock&& bulk) {
  const std::int32_t first_steiner = band.spec.split_point_count;
  TetBlock whole = join_band_and_bulk(std::move(band.band), std::move(bulk), band.band_steiner, band.band_tets, first_steiner);
  BandMarks marks(whole.tets, whole.neighbours, band.spec);
  marks.enter(band.crossings);
  PieceBand grown = split_by_depth(std::move(whole), marks.take_depth(), first_steiner);
  grown.links = band_part_links(grown.band, band.spec);
  grown.index = band.index;
  return grown;
}

std::vector<std::vector<std::int8_t>> mark_bands(const std::vector<const std::vector<Tet>*>& tets,
                                                 const std::vector<const std::vector<Tet>*>& neighbours,
                                                 const BandSpec& spec) {
  std::vector<BandMarks> marks;
  marks.reserve(tets.size());
  for (std::size_t p = 0; p < tets.size(); ++p) marks.emplace_back(*tets[p], *neighbours[p], spec);
  // (Where a piece is thicker than a tet, a star tet's cap face holds its removed vertex and the
  // tet across is a star tet too; a tet of a thin piece may have its cap face on one plane and its
  // removed vertex on the other.)
  for (bool grew = true; grew;) {
    grew = false;
    for (std::size_t p = 0; p < marks.size(); ++p) {
      const std::vector<CapCrossing> crossing = marks[p].crossings();
      if (p > 0) grew = marks[p - 1].enter(crossing) || grew;
      if (p + 1 < marks.size()) grew = marks[p + 1].enter(crossing) || grew;
    }
  }
  std::vector<std::vector<std::int8_t>> depths;
  depths.reserve(marks.size());
  for (auto& m : marks) depths.push_back(m.take_depth());
  return depths;
}

}  // namespace partet
