// Sorting (key, index) pairs (internal header).
#pragma once
#include <cstddef>
#include <utility>
#include <vector>

#include "common/radix_sort.hpp"

namespace partet {

using Keyed = std::pair<double, std::size_t>;

// A key for sort_keyed. Keys must not be NaN.
inline Keyed keyed(double key, std::size_t index) { return {key + 0.0, index}; }

// By key, then index: the order of std::sort. The pairs must come in increasing index order (as
// made by a loop over the indices): the radix sort keeps that order among equal keys (many
// vertices of a CAD part share a coordinate).
inline void sort_keyed(std::vector<Keyed>& pairs, unsigned threads = 1) {
  radix_sort(
      pairs, [](const Keyed& p) { return ordered_bits(p.first); }, threads);
}

}  // namespace partet
