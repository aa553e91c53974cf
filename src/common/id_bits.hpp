// The distinct ids of many uses (internal header): for ids up to about the number of points of a
// mesh one bit each, far smaller than listing every use of each id and sorting them out.
#pragma once
#include <algorithm>
#include <cstdint>
#include <vector>

namespace partet {

// The distinct ids `give` gives, ascending. give(f) calls f(id) for every use of an id; it is
// called twice (first to size the set). One bit per id up to the largest when that takes no more
// than listing the uses (dense ids: a mesh's points), else a sorted list (sparse 64-bit ids).
template <class T, class GiveIds>
std::vector<T> distinct_ascending(GiveIds give) {
  std::uint64_t high = 0, uses = 0;
  give([&](std::uint64_t id) { high = std::max(high, id), ++uses; });
  std::vector<T> ids;
  if (uses == 0) return ids;
  if (high / 64 <= uses) {
    std::vector<std::uint64_t> bits(static_cast<std::size_t>(high / 64) + 1, 0);
    give([&](std::uint64_t id) { bits[static_cast<std::size_t>(id / 64)] |= std::uint64_t{1} << (id % 64); });
    for (std::size_t word = 0; word < bits.size(); ++word)
      for (std::uint64_t w = bits[word]; w != 0; w &= w - 1)
        ids.push_back(static_cast<T>(64 * word + static_cast<std::uint64_t>(__builtin_ctzll(w))));
    return ids;
  }
  ids.reserve(static_cast<std::size_t>(uses));
  give([&](std::uint64_t id) { ids.push_back(static_cast<T>(id)); });
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

}  // namespace partet
