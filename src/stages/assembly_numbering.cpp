#include "stages/assembly_numbering.hpp"

#include <algorithm>
#include <string>

#include "partet/errors.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

std::vector<std::int64_t> before_each(const std::vector<std::int64_t>& counts) {
  std::vector<std::int64_t> before(counts.size() + 1, 0);
  for (std::size_t p = 0; p < counts.size(); ++p) before[p + 1] = before[p] + counts[p];
  return before;
}

}  // namespace

void check_int32_sizes(std::size_t tets, std::size_t points) {
  if (points > static_cast<std::size_t>(INT32_MAX))
    throw MeshingError(FailureKind::other, -1,
                       "the mesh has more than 2^31 points, more than one process can hold as one mesh (it numbers "
                       "them with int32); a run on several ranks that needs no assembled mesh writes it from its parts");
  if (tets > static_cast<std::size_t>(INT32_MAX))
    throw MeshingError(FailureKind::other, -1,
                       "the mesh has more than 2^31 tetrahedra, more than one process can hold as one mesh (it numbers "
                       "them with int32); a run on several ranks that needs no assembled mesh writes it from its parts");
}

AssemblyNumbering::AssemblyNumbering(AssemblyPoints points, const TetMesh& healed_band, bool drop_unused,
                                     const std::vector<std::int32_t>& used_elsewhere)
    : split_points_(points.split_points),
      steiner_before_(before_each(points.steiner_counts)),
      band_steiner_(std::move(points.band_steiner)) {
  std::vector<std::int64_t> band_counts;
  for (const auto& steiner : band_steiner_) band_counts.push_back(static_cast<std::int64_t>(steiner.size()));
  band_before_ = before_each(band_counts);
  healing_first_band_ = split_points_ + band_before_.back();
  const auto band_points = static_cast<std::int64_t>(healed_band.points.size());
  if (band_points < healing_first_band_ ||
      points.band_used_before.size() != static_cast<std::size_t>(healing_first_band_) ||
      points.referenced.size() != static_cast<std::size_t>(split_points_))
    throw InternalError("the healed band does not match the welded pieces");
  welded_ = healing_first_welded() + (band_points - healing_first_band_);
  // Only the ids that go are kept (a few per cut vertex): no array over every point.
  if (drop_unused) {
    std::vector<char> used = used_vertices(healed_band.points.size(), healed_band.tets);
    for (const std::int32_t v : used_elsewhere) used.at(static_cast<std::size_t>(v)) = 1;
    const std::vector<bool>& before = points.band_used_before;
    auto stays = [&](std::int64_t band_id) { return used[band_id] || !before[band_id]; };
    for (std::int32_t v = 0; v < split_points_; ++v)
      if (!(points.referenced[v] && stays(v))) dropped_.push_back(v);
    for (std::size_t p = 0; p < band_steiner_.size(); ++p)  // ascending: a band keeps its piece's order
      for (std::size_t j = 0; j < band_steiner_[p].size(); ++j)
        if (!stays(split_points_ + band_before_[p] + static_cast<std::int64_t>(j)))
          dropped_.push_back(welded_steiner(p, band_steiner_[p][j]));
    for (std::int64_t h = healing_first_band_; h < band_points; ++h)
      if (!used[h]) dropped_.push_back(healing_first_welded() + (h - healing_first_band_));
  }
  if (!std::is_sorted(dropped_.begin(), dropped_.end()))
    throw InternalError("a band's Steiner points are not in their piece's order");
  kept_ = welded_ - static_cast<std::int64_t>(dropped_.size());
  const auto split_end = std::lower_bound(dropped_.begin(), dropped_.end(), split_points_);
  dropped_split_ = std::make_shared<const std::vector<std::int32_t>>(dropped_.begin(), split_end);
}

std::int64_t AssemblyNumbering::of_welded(std::int64_t w) const {
  const auto gone = std::lower_bound(dropped_.begin(), dropped_.end(), w);
  if (gone != dropped_.end() && *gone == w) return -1;
  return w - (gone - dropped_.begin());
}

BulkNumbering AssemblyNumbering::for_bulk(std::size_t p) const {
  BulkNumbering bulk;
  bulk.split_points = split_points_;
  const std::int64_t first = welded_steiner(p, 0), end = welded_steiner(p + 1, 0);
  const auto from = std::lower_bound(dropped_.begin(), dropped_.end(), first);
  const auto to = std::lower_bound(dropped_.begin(), dropped_.end(), end);
  bulk.dropped_split = dropped_split_;
  for (auto it = from; it != to; ++it) bulk.dropped_steiner.push_back(static_cast<std::int32_t>(*it - first));
  // Every Steiner point of the piece before its first that stays goes: that one lands where the
  // piece's first would.
  bulk.first_steiner = first - (from - dropped_.begin());
  return bulk;
}

std::int32_t BulkNumbering::split_kept_below(std::int32_t n) const {
  return n - static_cast<std::int32_t>(std::lower_bound(dropped_split->begin(), dropped_split->end(), n) -
                                       dropped_split->begin());
}

void number_bulk(TetBlock& bulk, const BulkNumbering& share, std::int32_t first_steiner) {
  if (bulk.numbered) return;
  const std::int32_t to_welded = share.split_points - first_steiner;  // a Steiner point's provisional id to welded
  for (Tet& t : bulk.tets)
    for (auto& v : t)
      if ((v = share(v < first_steiner ? v : v + to_welded)) < 0)
        throw InternalError("a point the assembly drops is used by a tet of a bulk");
  bulk.ids = share.ids();
  if (!share.dropped_steiner.empty()) {
    std::size_t kept = 0;
    auto gone = share.dropped_steiner.begin();
    for (std::size_t i = 0; i < bulk.steiner_points.size(); ++i) {
      if (gone != share.dropped_steiner.end() && *gone == static_cast<std::int32_t>(i)) {
        ++gone;
        continue;
      }
      bulk.steiner_points[kept++] = bulk.steiner_points[i];
    }
    bulk.steiner_points.resize(kept);
  }
  bulk.numbered = true;
}

std::int32_t BulkNumbering::searched(std::int32_t v) const {
  auto shifted = [](const std::vector<std::int32_t>& dropped, std::int32_t i) -> std::int32_t {
    const auto below = std::lower_bound(dropped.begin(), dropped.end(), i);
    if (below != dropped.end() && *below == i) return -1;
    return i - static_cast<std::int32_t>(below - dropped.begin());
  };
  if (v < split_points) return shifted(*dropped_split, v);
  const std::int32_t i = shifted(dropped_steiner, v - split_points);
  return i < 0 ? -1 : kept_split() + i;
}

std::int64_t AssemblyNumbering::welded_of_band(std::int32_t v) const {
  if (v < split_points_) return v;
  if (v >= healing_first_band_) return healing_first_welded() + (v - healing_first_band_);
  const std::int64_t b = v - split_points_;
  const auto p = static_cast<std::size_t>(std::upper_bound(band_before_.begin(), band_before_.end(), b) -
                                          band_before_.begin() - 1);
  return welded_steiner(p, band_steiner_[p][static_cast<std::size_t>(b - band_before_[p])]);
}

}  // namespace partet
