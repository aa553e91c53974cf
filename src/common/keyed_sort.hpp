// Sorting (key, index) pairs (internal header).
#pragma once
#include <algorithm>
#include <boost/sort/spreadsort/float_sort.hpp>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace partet {

using Keyed = std::pair<double, std::size_t>;

// A key for sort_keyed: -0.0 becomes 0.0, so the radix passes (on the bits) and the comparison
// (on the values) agree on the order. Keys must not be NaN.
inline Keyed keyed(double key, std::size_t index) { return {key + 0.0, index}; }

// By key, then index: the order of std::sort, radix-like on the key's bits (spreadsort), about
// twice as fast on the millions of vertices a partition orders along its axis. Spreadsort leaves
// a large group of equal keys as it found it, so the groups (many vertices of a CAD part share a
// coordinate) are put in index order afterwards.
inline void sort_keyed(std::vector<Keyed>& pairs) {
  boost::sort::spreadsort::float_sort(
      pairs.begin(), pairs.end(),
      [](const Keyed& p, unsigned offset) {
        return boost::sort::spreadsort::float_mem_cast<double, std::int64_t>(p.first) >> offset;
      },
      [](const Keyed& a, const Keyed& b) { return a.first < b.first; });
  for (auto group = pairs.begin(); group != pairs.end();) {
    auto end = group + 1;
    while (end != pairs.end() && end->first == group->first) ++end;
    if (end - group > 1) std::sort(group, end);
    group = end;
  }
}

}  // namespace partet
