#include "stages/seam_chains.hpp"

#include <algorithm>

#include "stages/seam_rounds.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

// The tets within `reach` layers (across faces) of a tet holding a vertex to remove, ascending.
// Marks by bit, not by an id per tet: the whole mesh may have tens of millions of tets and the
// band a few percent of them.
std::vector<std::int32_t> band_tets(const TetMesh& mesh, std::int32_t first, const std::vector<int>& group, int reach) {
  std::vector<bool> reached(mesh.tets.size(), false);
  std::vector<std::int32_t> band, layer;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    if (TetRemoved(mesh.tets[t], first, group).count > 0) {
      reached[t] = true;
      layer.push_back(static_cast<std::int32_t>(t));
    }
  for (int depth = 0;; ++depth) {
    band.insert(band.end(), layer.begin(), layer.end());
    if (depth == reach || layer.empty()) break;
    std::vector<std::int32_t> next;
    for (auto t : layer)
      for (auto nb : mesh.neighbours[t])
        if (nb >= 0 && !reached[nb]) reached[nb] = true, next.push_back(nb);
    layer = std::move(next);
  }
  std::sort(band.begin(), band.end());
  return band;
}

}  // namespace

SeamChains seam_chains(const TetMesh& mesh, std::int32_t first, const std::vector<int>& group, int groups, int reach) {
  const std::vector<std::int32_t> band = band_tets(mesh, first, group, reach);
  auto position = [&](std::int32_t t) {
    auto it = std::lower_bound(band.begin(), band.end(), t);
    return it != band.end() && *it == t ? static_cast<std::int32_t>(it - band.begin()) : -1;
  };
  // The band's parts joined through faces...
  DisjointSets parts(0, band.size());
  for (std::size_t i = 0; i < band.size(); ++i)
    for (auto nb : mesh.neighbours[band[i]])
      if (nb >= 0 && nb < band[i]) {
        const std::int32_t at = position(nb);
        if (at >= 0) parts.join(static_cast<std::int32_t>(i), at);
      }
  // ...join the groups with vertices in them (a group may lie in several: a cut's loops).
  DisjointSets joined(0, static_cast<std::size_t>(groups));
  std::vector<int> group_of_part(band.size(), -1);
  std::vector<char> present(static_cast<std::size_t>(groups), 0);
  for (std::size_t i = 0; i < band.size(); ++i) {
    const TetRemoved found(mesh.tets[band[i]], first, group);
    for (int j = 0; j < found.count; ++j) {
      const int g = found.group[j];
      present[g] = 1;
      int& seen = group_of_part[parts.find(static_cast<std::int32_t>(i))];
      if (seen < 0)
        seen = g;
      else
        joined.join(g, seen);
    }
  }
  SeamChains chains;
  chains.of_group.assign(static_cast<std::size_t>(groups), -1);
  std::vector<int> number(static_cast<std::size_t>(groups), -1);
  for (int g = 0; g < groups; ++g) {
    if (!present[g]) continue;
    int& n = number[joined.find(g)];
    if (n < 0) n = chains.count++;
    chains.of_group[g] = n;
  }
  return chains;
}

}  // namespace partet
