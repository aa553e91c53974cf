// Work items spread over ranks by their sizes (internal header).
#pragma once
#include <cstddef>
#include <vector>

namespace partet {

// Each item (sizes given largest first) goes to the rank with the least work so far (longest
// processing time first: no rank ends with more than the average plus one item): by item, its
// rank. Ties go to the highest rank, so that rank 0, which also hands the items out, gets fewer.
inline std::vector<int> balanced_ranks(const std::vector<std::size_t>& sizes, int ranks) {
  std::vector<std::size_t> load(static_cast<std::size_t>(ranks > 0 ? ranks : 1), 0);
  std::vector<int> rank_of;
  rank_of.reserve(sizes.size());
  for (const std::size_t size : sizes) {
    std::size_t best = load.size() - 1;
    for (std::size_t r = load.size(); r-- > 0;)
      if (load[r] < load[best]) best = r;
    load[best] += size;
    rank_of.push_back(static_cast<int>(best));
  }
  return rank_of;
}

}  // namespace partet
