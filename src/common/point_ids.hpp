// How a block of tets names the mesh's points (internal header). A block keeps 32-bit ids however
// many points the whole mesh has: ids below `from` are the mesh's own (the split surface's points
// that stay, the first rows of every mesh), and id v >= from is the mesh's point v + shift (a bulk:
// its own Steiner points, rows in a run) or table[v - from] (the healed band, a piece file's part
// of it: points from anywhere). Both keep the order of ids, so a face's vertices sorted in a
// block's ids are sorted in the mesh's.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "partet/mesh_types.hpp"

namespace partet {

// A tet in the whole mesh's ids: a spread mesh may have 2^31 points or more.
using GlobalTet = std::array<std::int64_t, 4>;

struct PointIds {
  std::int32_t from = INT32_MAX;
  std::int64_t shift = 0;
  const std::int64_t* table = nullptr;  // not owned

  std::int64_t operator()(std::int32_t v) const {
    if (v < from) return v;
    return table ? table[v - from] : v + shift;
  }
  GlobalTet operator()(const Tet& t) const { return {(*this)(t[0]), (*this)(t[1]), (*this)(t[2]), (*this)(t[3])}; }
  // Every id is the mesh's own.
  bool as_is() const { return from == INT32_MAX || (table == nullptr && shift == 0); }
};

// Tets in the whole mesh's ids made compact: their ids through a table of the ids they use
// (PointIds{0, 0, table.data()}), for a block of tets that came from anywhere.
struct CompactTets {
  std::vector<Tet> tets;
  std::vector<std::int64_t> table;  // ascending
  PointIds ids() const { return {0, 0, table.data()}; }
};
CompactTets compact_tets(const std::vector<GlobalTet>& tets);

}  // namespace partet
