#include "stages/kept_band_parts.hpp"

#include <algorithm>
#include <string>

#include "partet/errors.hpp"

namespace partet {

std::set<int> chains_of(const BandPartPlan& plan) {
  std::set<int> chains;
  for (const int chain : plan.chain_of_part)
    if (chain >= 0) chains.insert(chain);
  return chains;
}

std::vector<std::int32_t> split_points_of(const std::vector<Tet>& tets, std::int32_t first_steiner) {
  std::vector<std::int32_t> points;
  for (const Tet& tet : tets)
    for (const std::int32_t v : tet)
      if (v < first_steiner) points.push_back(v);
  std::sort(points.begin(), points.end());
  points.erase(std::unique(points.begin(), points.end()), points.end());
  return points;
}

std::vector<std::int32_t> merged_split_points(const std::vector<const std::vector<std::int32_t>*>& parts) {
  std::vector<std::int32_t> ids;
  for (const std::vector<std::int32_t>* part : parts) {
    const auto middle = static_cast<std::ptrdiff_t>(ids.size());
    ids.insert(ids.end(), part->begin(), part->end());
    std::inplace_merge(ids.begin(), ids.begin() + middle, ids.end());
  }
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

void KeptBandParts::keep(PieceBand& split) {
  Part& part = parts_[split.index];
  split.band_kept = true;
  split.band_tet_count = static_cast<std::int64_t>(split.band.tets.size());
  split.band_split_points = split_points_of(split.band.tets, split.first_steiner);
  part.band.in = true;
  part.band.tets = std::move(split.band.tets);
  part.band.neighbours = std::move(split.band.neighbours);
  part.band.steiner_points = split.band.steiner_points;  // (the welder needs them too)
  part.band_steiner = split.band_steiner;
  part.band_tets = std::move(split.band_tets);
  split.band.tets.clear();
  split.band.neighbours.clear();
  split.band_tets.clear();
}

void KeptBandParts::fill(BandToGrow& band) {
  const auto it = parts_.find(band.index);
  if (it == parts_.end()) throw InternalError("no band part of piece " + std::to_string(band.index) + " is kept here");
  band.band = std::move(it->second.band);
  band.band_steiner = std::move(it->second.band_steiner);
  band.band_tets = std::move(it->second.band_tets);
  parts_.erase(it);
}

PieceBand KeptBandParts::take(int piece) {
  const auto it = parts_.find(piece);
  if (it == parts_.end()) throw InternalError("no band part of piece " + std::to_string(piece) + " is kept here");
  PieceBand band;
  band.index = piece;
  band.band = std::move(it->second.band);
  band.band_steiner = std::move(it->second.band_steiner);
  band.band_tets = std::move(it->second.band_tets);
  parts_.erase(it);
  return band;
}

void KeptBandParts::cut_shares(const std::vector<BandPartPlan>& plans, const std::vector<int>& order,
                               const std::function<void(int, std::vector<ChainShare>&&)>& each) const {
  struct Cut {
    const TetBlock* band;
    const BandPartPlan* plan;
    BandPartChains chains;
  };
  std::vector<Cut> cuts;  // in piece order
  for (const BandPartPlan& plan : plans) {
    const auto it = parts_.find(plan.place.piece);
    if (it == parts_.end())
      throw InternalError("no band part of piece " + std::to_string(plan.place.piece) + " is kept here");
    cuts.push_back({&it->second.band, &plan, band_part_chains(it->second.band, plan.chain_of_part)});
  }
  std::sort(cuts.begin(), cuts.end(),
            [](const Cut& a, const Cut& b) { return a.plan->place.piece < b.plan->place.piece; });
  for (const int chain : order) {
    std::vector<ChainShare> shares;
    for (const Cut& cut : cuts) {
      const auto& chains = cut.chains.chains;
      const auto at = std::lower_bound(chains.begin(), chains.end(), chain);
      if (at == chains.end() || *at != chain) continue;
      shares.push_back(
          chain_share(*cut.band, cut.chains, static_cast<std::size_t>(at - chains.begin()), cut.plan->place));
    }
    if (!shares.empty()) each(chain, std::move(shares));
  }
}

}  // namespace partet
