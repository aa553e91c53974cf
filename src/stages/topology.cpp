#include "stages/topology.hpp"

#include <algorithm>
#include <utility>

#include <boost/sort/spreadsort/integer_sort.hpp>

#include "partet/errors.hpp"

namespace partet {

std::vector<Tet> compute_neighbours(const std::vector<Tet>& tets, std::size_t vertex_count, CrowdedFace crowded) {
  std::vector<Tet> neighbours(tets.size(), Tet{-1, -1, -1, -1});
  for_each_face(tets, vertex_count, [&](const FaceSlot* group, std::size_t count) {
    if (count > 2 && crowded == CrowdedFace::throw_error)
      throw InternalError("a triangle is shared by more than two tetrahedra");
    if (count != 2) return;
    const std::uint32_t a = group[0].slot, b = group[1].slot;
    neighbours[a / 4][a % 4] = static_cast<std::int32_t>(b / 4);
    neighbours[b / 4][b % 4] = static_cast<std::int32_t>(a / 4);
  });
  return neighbours;
}

std::vector<Tet> compute_neighbours(const std::vector<Tet>& tets) {
  std::int32_t largest = -1;
  for (const Tet& t : tets)
    for (auto v : t) largest = std::max(largest, v);
  return compute_neighbours(tets, static_cast<std::size_t>(largest + 1));
}

void connect_open_faces(const std::vector<Tet>& tets, std::vector<Tet>& neighbours,
                        const std::vector<std::int32_t>* candidates) {
  std::vector<std::uint64_t> faces;
  auto collect = [&](std::size_t t) {
    for (int j = 0; j < 4; ++j)
      if (neighbours[t][j] < 0) faces.push_back(4 * static_cast<std::uint64_t>(t) + j);
  };
  if (candidates) {
    for (auto t : *candidates) collect(static_cast<std::size_t>(t));
  } else {
    for (std::size_t t = 0; t < tets.size(); ++t) collect(t);
  }
  connect_faces(tets, neighbours, faces);
}

void connect_faces(const std::vector<Tet>& tets, std::vector<Tet>& neighbours, const std::vector<std::uint64_t>& faces) {
  struct OpenFace {
    FaceKey key;
    std::uint64_t slot;  // 4 * tet + j
    bool operator<(const OpenFace& o) const { return key < o.key || (key == o.key && slot < o.slot); }
  };
  std::vector<OpenFace> open;
  open.reserve(faces.size());
  for (const std::uint64_t slot : faces) open.push_back({FaceKey(outward_face(tets[slot / 4], slot % 4)), slot});
  std::sort(open.begin(), open.end());
  for (std::size_t i = 0; i < open.size();) {
    std::size_t e = i + 1;
    while (e < open.size() && open[e].key == open[i].key) ++e;
    if (e - i > 2) throw InternalError("an open triangle is shared by more than two tetrahedra");
    if (e - i == 2) {
      const std::uint64_t a = open[i].slot, b = open[i + 1].slot;
      neighbours[a / 4][a % 4] = static_cast<std::int32_t>(b / 4);
      neighbours[b / 4][b % 4] = static_cast<std::int32_t>(a / 4);
    }
    i = e;
  }
}

std::vector<std::int32_t> renumber_locally(std::vector<Triangle>& triangles, std::vector<std::int32_t>& scratch) {
  // Each vertex once (marked in scratch), then sorted: a closed surface has about half as many
  // vertices as triangles, so this sorts a sixth of the corners (10.9M faces: 1.9 s less).
  std::vector<std::int32_t> ids;
  ids.reserve(triangles.size() / 2 + 3);
  for (const auto& t : triangles)
    for (std::int32_t v : t)
      if (scratch[v] == -1) {
        scratch[v] = -2;
        ids.push_back(v);
      }
  boost::sort::spreadsort::integer_sort(ids.begin(), ids.end());
  for (std::size_t i = 0; i < ids.size(); ++i) scratch[ids[i]] = static_cast<std::int32_t>(i);
  for (auto& t : triangles)
    for (auto& v : t) v = scratch[v];
  for (auto id : ids) scratch[id] = -1;
  return ids;
}

void sort_triangles(std::vector<Triangle>& triangles) {
  for (Triangle& t : triangles) std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  std::sort(triangles.begin(), triangles.end());
}

std::vector<std::int32_t> renumber_locally(std::vector<Triangle>& triangles) {
  std::vector<std::int32_t> ids;
  ids.reserve(3 * triangles.size());
  for (const auto& t : triangles) ids.insert(ids.end(), t.begin(), t.end());
  boost::sort::spreadsort::integer_sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  ids.shrink_to_fit();
  for (auto& t : triangles)
    for (auto& v : t) v = static_cast<std::int32_t>(std::lower_bound(ids.begin(), ids.end(), v) - ids.begin());
  return ids;
}

std::vector<std::int32_t> renumber_locally(std::vector<Tet>& tets) {
  using Corner = std::pair<std::int32_t, std::uint32_t>;  // (id, 4 * tet + j)
  std::vector<Corner> corners;
  corners.reserve(4 * tets.size());
  for (std::size_t t = 0; t < tets.size(); ++t)
    for (std::uint32_t j = 0; j < 4; ++j) corners.emplace_back(tets[t][j], static_cast<std::uint32_t>(4 * t) + j);
  boost::sort::spreadsort::integer_sort(
      corners.begin(), corners.end(), [](const Corner& c, unsigned shift) { return c.first >> shift; },
      [](const Corner& a, const Corner& b) { return a.first < b.first; });
  std::vector<std::int32_t> ids;
  for (const auto& [id, corner] : corners) {
    if (ids.empty() || ids.back() != id) ids.push_back(id);
    tets[corner / 4][corner % 4] = static_cast<std::int32_t>(ids.size() - 1);
  }
  ids.shrink_to_fit();
  return ids;
}

std::vector<std::int32_t> compact_ids(const std::vector<char>& used) {
  std::vector<std::int32_t> id(used.size(), -1);
  std::int32_t next = 0;
  for (std::size_t i = 0; i < used.size(); ++i)
    if (used[i]) id[i] = next++;
  return id;
}

std::int32_t append_local_mesh(const LocalTetMesh& local, const std::vector<std::int32_t>& global_ids,
                               std::vector<Point3>& points, std::vector<Tet>& tets, std::vector<Tet>& neighbours) {
  const auto surface_count = static_cast<std::int32_t>(global_ids.size());
  const auto steiner_base = static_cast<std::int64_t>(points.size()) - surface_count;
  points.insert(points.end(), local.steiner_points.begin(), local.steiner_points.end());
  const auto tet_base = static_cast<std::int32_t>(tets.size());
  for (std::size_t t = 0; t < local.tets.size(); ++t) {
    Tet g, nb;
    for (int j = 0; j < 4; ++j) {
      const auto v = local.tets[t][j];
      g[j] = v < surface_count ? global_ids[v] : static_cast<std::int32_t>(steiner_base + v);
      nb[j] = local.neighbours[t][j] >= 0 ? local.neighbours[t][j] + tet_base : -1;
    }
    tets.push_back(g);
    neighbours.push_back(nb);
  }
  return tet_base;
}

}  // namespace partet
