// Band parts kept where they were split (internal header). The rank that meshed a piece keeps
// its band part beside its bulk, so rank 0 never holds the band's tets (issue 22): the welder
// gets what it needs of each part (PieceBand::band_kept), the part grows where it is, the chains'
// shares are cut from it there, and it comes back only when the band must be welded after all.
#pragma once
#include <cstdint>
#include <functional>
#include <map>
#include <set>
#include <vector>

#include "stages/seam_band.hpp"
#include "stages/seam_chain_band.hpp"

namespace partet {

// One piece's band part in the chains' plan: where it goes in the band (place.steiner_from: the
// id of its first Steiner point where it is kept) and the chain of each of its parts
// (SeamChainPlan::chain_of_part).
struct BandPartPlan {
  BandPartPlace place;
  std::vector<int> chain_of_part;
};

// The split surface's points (those below first_steiner) a band part's tets use, ascending: what
// the chains' splits need of it (chain_split).
std::vector<std::int32_t> split_points_of(const std::vector<Tet>& tets, std::int32_t first_steiner);
// Those of several band parts (each ascending), merged: ascending, each once.
std::vector<std::int32_t> merged_split_points(const std::vector<const std::vector<std::int32_t>*>& parts);

// The seam chains the parts of plan's band part belong to, each once.
std::set<int> chains_of(const BandPartPlan& plan);

class KeptBandParts {
 public:
  // Keeps split's band part (its tets, neighbours and band_tets), leaving in split what the welder
  // needs of it (band_kept, band_tet_count, band_split_points).
  void keep(PieceBand& split);
  bool holds(int piece) const { return parts_.count(piece) != 0; }
  void forget(int piece) { parts_.erase(piece); }
  void clear() { parts_.clear(); }
  // A band sent to grow without its band part (BandToGrow::band_kept): the part kept here moved into it.
  void fill(BandToGrow& band);
  // Piece's band part (band, band_steiner, band_tets), given back once.
  PieceBand take(int piece);
  // Each chain's shares of the band parts kept here (chain_share), chain after chain in `order`,
  // skipping chains without one here; a chain's shares in piece order.
  void cut_shares(const std::vector<BandPartPlan>& plans, const std::vector<int>& order,
                  const std::function<void(int chain, std::vector<ChainShare>&& shares)>& each) const;

 private:
  struct Part {
    TetBlock band;
    std::vector<std::int32_t> band_steiner, band_tets;
  };
  std::map<int, Part> parts_;  // by piece
};

}  // namespace partet
