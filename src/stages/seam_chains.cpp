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

// The chains of the groups whose vertices lie in the parts `parts` joins: removed(i, add) calls
// add(v) for each vertex v to remove in part i (a group may lie in several parts: a cut's loops).
// With chain_of_part, also the chain of each part (-1: no vertex to remove where it is joined).
template <class ForEachRemoved>
SeamChains join_groups(DisjointSets& parts, std::int32_t first, const std::vector<int>& group, int groups,
                       const ForEachRemoved& removed, std::vector<int>* chain_of_part = nullptr) {
  DisjointSets joined(0, static_cast<std::size_t>(groups));
  std::vector<int> group_of_part(parts.size(), -1);
  std::vector<char> present(static_cast<std::size_t>(groups), 0);
  for (std::size_t i = 0; i < parts.size(); ++i)
    removed(i, [&](std::int32_t v) {
      const std::int64_t at = static_cast<std::int64_t>(v) - first;
      if (at < 0 || at >= static_cast<std::int64_t>(group.size()) || group[at] < 0) return;
      const int g = group[at];
      present[g] = 1;
      int& seen = group_of_part[parts.find(static_cast<std::int32_t>(i))];
      if (seen < 0)
        seen = g;
      else
        joined.join(g, seen);
    });
  SeamChains chains;
  chains.of_group.assign(static_cast<std::size_t>(groups), -1);
  std::vector<int> number(static_cast<std::size_t>(groups), -1);
  for (int g = 0; g < groups; ++g) {
    if (!present[g]) continue;
    int& n = number[joined.find(g)];
    if (n < 0) n = chains.count++;
    chains.of_group[g] = n;
  }
  if (chain_of_part) {
    chain_of_part->assign(parts.size(), -1);
    for (std::size_t i = 0; i < parts.size(); ++i) {
      const int g = group_of_part[parts.find(static_cast<std::int32_t>(i))];
      if (g >= 0) (*chain_of_part)[i] = chains.of_group[g];
    }
  }
  return chains;
}

}  // namespace

SeamChains seam_chains(const TetMesh& mesh, std::int32_t first, const std::vector<int>& group, int groups, int reach) {
  const std::vector<std::int32_t> band = band_tets(mesh, first, group, reach);
  auto position = [&](std::int32_t t) {
    auto it = std::lower_bound(band.begin(), band.end(), t);
    return it != band.end() && *it == t ? static_cast<std::int32_t>(it - band.begin()) : -1;
  };
  // The band's parts joined through faces, then the groups with vertices in them.
  DisjointSets parts(0, band.size());
  for (std::size_t i = 0; i < band.size(); ++i)
    for (auto nb : mesh.neighbours[band[i]])
      if (nb >= 0 && nb < band[i]) {
        const std::int32_t at = position(nb);
        if (at >= 0) parts.join(static_cast<std::int32_t>(i), at);
      }
  return join_groups(parts, first, group, groups, [&](std::size_t i, const auto& add) {
    for (auto v : mesh.tets[band[i]]) add(v);
  });
}

std::vector<std::int32_t> band_part_labels(const TetBlock& band) {
  std::vector<std::int32_t> part;
  label_tet_regions(band.neighbours, [](std::size_t) { return true; }, [](std::size_t, int) { return true; }, part);
  return part;
}

BandPartLinks band_part_links(const TetBlock& band, const BandSpec& spec) {
  const std::vector<std::int32_t> part = band_part_labels(band);
  BandPartLinks links;
  links.removed.resize(part.empty() ? 0 : static_cast<std::size_t>(*std::max_element(part.begin(), part.end()) + 1));
  links.tets.assign(links.removed.size(), 0);
  for (std::size_t t = 0; t < band.tets.size(); ++t) {
    const Tet& tet = band.tets[t];
    ++links.tets[part[t]];
    for (auto v : tet)
      if (spec.removes(v)) links.removed[part[t]].push_back(v);
    for (int j = 0; j < 4; ++j) {
      if (band.neighbours[t][j] >= 0) continue;
      const Triangle face = outward_face(tet, j);
      if (spec.on_planes(face[0]) && spec.on_planes(face[1]) && spec.on_planes(face[2]))
        links.cap_faces.emplace_back(FaceKey(face), part[t]);
    }
  }
  for (auto& vertices : links.removed) {
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  }
  std::sort(links.cap_faces.begin(), links.cap_faces.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  return links;
}

SeamChains seam_chains(const std::vector<BandPartLinks>& pieces, std::int32_t first, const std::vector<int>& group,
                       int groups) {
  // Every piece's parts in one numbering, joined where two pieces have the same cap face.
  std::vector<std::size_t> offset(pieces.size() + 1, 0);
  for (std::size_t p = 0; p < pieces.size(); ++p) offset[p + 1] = offset[p] + pieces[p].removed.size();
  std::vector<std::pair<FaceKey, std::int32_t>> faces;
  for (std::size_t p = 0; p < pieces.size(); ++p)
    for (const auto& [key, part] : pieces[p].cap_faces)
      faces.emplace_back(key, static_cast<std::int32_t>(offset[p] + static_cast<std::size_t>(part)));
  std::sort(faces.begin(), faces.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  DisjointSets parts(0, offset.back());
  for (std::size_t i = 1; i < faces.size(); ++i)
    if (faces[i].first == faces[i - 1].first) parts.join(faces[i].second, faces[i - 1].second);
  std::vector<std::size_t> piece_of(offset.back());
  for (std::size_t p = 0; p < pieces.size(); ++p)
    std::fill(piece_of.begin() + static_cast<std::ptrdiff_t>(offset[p]),
              piece_of.begin() + static_cast<std::ptrdiff_t>(offset[p + 1]), p);
  std::vector<int> chain_of_part;
  SeamChains chains = join_groups(
      parts, first, group, groups,
      [&](std::size_t i, const auto& add) {
        const std::size_t p = piece_of[i];
        for (auto v : pieces[p].removed[i - offset[p]]) add(v);
      },
      &chain_of_part);
  for (std::size_t p = 0; p < pieces.size(); ++p)
    chains.of_part.emplace_back(chain_of_part.begin() + static_cast<std::ptrdiff_t>(offset[p]),
                                chain_of_part.begin() + static_cast<std::ptrdiff_t>(offset[p + 1]));
  return chains;
}

}  // namespace partet
