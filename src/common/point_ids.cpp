#include "common/point_ids.hpp"

#include <algorithm>

#include "partet/errors.hpp"

namespace partet {

CompactTets compact_tets(const std::vector<GlobalTet>& tets) {
  CompactTets compact;
  for (const GlobalTet& t : tets) compact.table.insert(compact.table.end(), t.begin(), t.end());
  std::sort(compact.table.begin(), compact.table.end());
  compact.table.erase(std::unique(compact.table.begin(), compact.table.end()), compact.table.end());
  if (compact.table.size() > static_cast<std::size_t>(INT32_MAX))
    throw InternalError("a block of tets uses more than 2^31 points");
  compact.tets.reserve(tets.size());
  for (const GlobalTet& t : tets) {
    Tet& c = compact.tets.emplace_back();
    for (int j = 0; j < 4; ++j)
      c[j] = static_cast<std::int32_t>(std::lower_bound(compact.table.begin(), compact.table.end(), t[j]) -
                                       compact.table.begin());
  }
  return compact;
}

}  // namespace partet
