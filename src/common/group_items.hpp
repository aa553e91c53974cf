// Grouping items by a small key (internal header).
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

namespace partet {

// Items 0..n-1 grouped by group_of(i) < groups, in index order within each group:
// order[start[g], start[g + 1]) are group g's. A counting sort, linear.
template <class GroupOf>
void group_items(std::size_t n, std::size_t groups, GroupOf group_of, std::vector<std::uint32_t>& order,
                 std::vector<std::size_t>& start) {
  start.assign(groups + 1, 0);
  for (std::size_t i = 0; i < n; ++i) ++start[group_of(i) + 1];
  for (std::size_t g = 1; g <= groups; ++g) start[g] += start[g - 1];
  order.resize(n);
  std::vector<std::size_t> next(start.begin(), start.end() - 1);
  for (std::size_t i = 0; i < n; ++i) order[next[group_of(i)]++] = static_cast<std::uint32_t>(i);
}

}  // namespace partet
