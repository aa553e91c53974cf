#include "stages/spread_mesh.hpp"

#include <algorithm>
#include <numeric>
#include <type_traits>
#include <utility>

#include "partet/errors.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

// A block's links in ascending order of their keys, sorted where the block is (on its owner),
// so that matching the blocks' faces needs no copy of them all (for_each_shared_face).
void sort_by_key(BlockLinks& links) {
  std::vector<std::uint32_t> order(links.keys.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return links.keys[a] < links.keys[b]; });
  auto permute = [&](auto& values) {
    std::remove_reference_t<decltype(values)> sorted;
    sorted.reserve(values.size());
    for (auto i : order) sorted.push_back(values[i]);
    values.swap(sorted);
  };
  permute(links.keys);
  permute(links.component);
  permute(links.face);
}

// Calls shared(a, i, b, j) for each open face two blocks share: key i of block a and key j of
// block b (a <= b). A merge of the blocks' ascending keys: no copy of them all, which as one
// sorted array was most of rank 0's peak at the end (docs/benchmarks.md).
template <class Shared>
void for_each_shared_face(const std::vector<BlockLinks>& blocks, const Shared& shared) {
  for (std::size_t b = 0; b < blocks.size(); ++b)
    if (!std::is_sorted(blocks[b].keys.begin(), blocks[b].keys.end()))
      throw InternalError("the links of a block of the spread mesh are not in order");
  using Head = std::pair<std::uint32_t, std::size_t>;  // block, position in its keys
  auto key = [&](const Head& h) -> const std::array<std::int64_t, 3>& { return blocks[h.first].keys[h.second]; };
  auto later = [&](const Head& x, const Head& y) { return key(y) < key(x) || (key(y) == key(x) && y.first < x.first); };
  std::vector<Head> heads;
  for (std::size_t b = 0; b < blocks.size(); ++b)
    if (!blocks[b].keys.empty()) heads.emplace_back(static_cast<std::uint32_t>(b), 0);
  std::make_heap(heads.begin(), heads.end(), later);
  auto pop = [&] {
    std::pop_heap(heads.begin(), heads.end(), later);
    Head h = heads.back();
    heads.pop_back();
    if (h.second + 1 < blocks[h.first].keys.size()) {
      heads.emplace_back(h.first, h.second + 1);
      std::push_heap(heads.begin(), heads.end(), later);
    }
    return h;
  };
  bool pending = false;  // `last` is a face not yet matched
  Head last{};
  while (!heads.empty()) {
    const Head h = pop();
    if (pending && key(h) == key(last)) {
      if (!heads.empty() && key(heads.front()) == key(h))
        throw InternalError("three open faces of the spread mesh are one triangle");
      shared(last.first, last.second, h.first, h.second);
      pending = false;
    } else {
      last = h;
      pending = true;
    }
  }
}

}  // namespace

BlockLinks block_links(const std::vector<Tet>& tets, const PointIds& ids, const std::vector<Tet>& neighbours,
                       bool every_open_face, std::int32_t input_vertices, const std::vector<std::uint64_t>& rim,
                       std::vector<std::int32_t>& label) {
  if (neighbours.size() != tets.size()) throw InternalError("a block's neighbours do not match its tets");
  BlockLinks links;
  const std::int32_t count = label_tet_regions(
      neighbours, [](std::size_t) { return true; }, [](std::size_t, int) { return true; }, label);
  links.first_tet.assign(static_cast<std::size_t>(count), -1);
  for (std::size_t t = 0; t < tets.size(); ++t)
    if (links.first_tet[label[t]] < 0) links.first_tet[label[t]] = static_cast<std::int32_t>(t);
  std::vector<char> on_rim;
  if (!every_open_face) {
    on_rim.assign(4 * tets.size(), 0);
    for (std::uint64_t slot : rim) on_rim.at(slot) = 1;
  }
  for (std::size_t t = 0; t < tets.size(); ++t)
    for (int j = 0; j < 4; ++j) {
      if (neighbours[t][j] >= 0) continue;
      const FaceKey key(outward_face(tets[t], j));
      // Ascending ids: the last is the largest, so a face has a point other than an input vertex
      // exactly when it is at least input_vertices.
      if (!every_open_face && !on_rim[4 * t + j] && key.v[2] < input_vertices) continue;
      links.keys.push_back({ids(key.v[0]), ids(key.v[1]), ids(key.v[2])});  // ids keep the order
      links.component.push_back(label[t]);
      links.face.push_back(4 * t + static_cast<std::uint64_t>(j));
    }
  sort_by_key(links);
  return links;
}

std::vector<std::vector<std::int32_t>> solids_of_blocks(const std::vector<BlockLinks>& blocks,
                                                        const std::vector<std::int64_t>& first_row) {
  // One node per component of each block, in block order.
  std::vector<std::size_t> node_base(blocks.size() + 1, 0);
  for (std::size_t b = 0; b < blocks.size(); ++b) node_base[b + 1] = node_base[b] + blocks[b].first_tet.size();
  DisjointSets sets(0, node_base.back());
  for_each_shared_face(blocks, [&](std::size_t a, std::size_t i, std::size_t b, std::size_t j) {
    sets.join(static_cast<std::int32_t>(node_base[a] + blocks[a].component[i]),
              static_cast<std::int32_t>(node_base[b] + blocks[b].component[j]));
  });
  // Each solid's first row: the least of its components' first rows.
  std::vector<std::int64_t> first(node_base.back(), INT64_MAX);
  for (std::size_t b = 0; b < blocks.size(); ++b)
    for (std::size_t c = 0; c < blocks[b].first_tet.size(); ++c) {
      const std::int32_t root = sets.find(static_cast<std::int32_t>(node_base[b] + c));
      first[root] = std::min(first[root], first_row[b] + blocks[b].first_tet[c]);
    }
  std::vector<std::int32_t> roots;
  for (std::size_t n = 0; n < first.size(); ++n)
    if (first[n] != INT64_MAX) roots.push_back(static_cast<std::int32_t>(n));
  std::sort(roots.begin(), roots.end(), [&](std::int32_t a, std::int32_t b) { return first[a] < first[b]; });
  std::vector<std::int32_t> solid_of_root(node_base.back(), 0);
  for (std::size_t i = 0; i < roots.size(); ++i) solid_of_root[roots[i]] = static_cast<std::int32_t>(i + 1);
  std::vector<std::vector<std::int32_t>> solids(blocks.size());
  for (std::size_t b = 0; b < blocks.size(); ++b)
    for (std::size_t c = 0; c < blocks[b].first_tet.size(); ++c)
      solids[b].push_back(solid_of_root[sets.find(static_cast<std::int32_t>(node_base[b] + c))]);
  return solids;
}

std::vector<std::vector<FaceAcross>> faces_across_blocks(const std::vector<BlockLinks>& blocks,
                                                         const std::vector<std::int64_t>& first_row) {
  for (const BlockLinks& block : blocks)
    if (block.face.size() != block.keys.size()) throw InternalError("a block's links name no faces");
  std::vector<std::vector<FaceAcross>> across(blocks.size());
  for_each_shared_face(blocks, [&](std::size_t a, std::size_t i, std::size_t b, std::size_t j) {
    const std::uint64_t face_a = blocks[a].face[i], face_b = blocks[b].face[j];
    across[a].push_back({face_a, first_row[b] + static_cast<std::int64_t>(face_b / 4)});
    across[b].push_back({face_b, first_row[a] + static_cast<std::int64_t>(face_a / 4)});
  });
  for (auto& faces : across) std::sort(faces.begin(), faces.end());
  return across;
}

std::vector<NeighbourRow> neighbour_rows(const std::vector<Tet>& neighbours, std::int64_t first_row,
                                         const std::vector<FaceAcross>& across, std::size_t from, std::size_t count) {
  std::vector<NeighbourRow> rows(count);
  for (std::size_t i = 0; i < count; ++i)
    for (int j = 0; j < 4; ++j) {
      const std::int32_t n = neighbours[from + i][j];
      rows[i][j] = n >= 0 ? first_row + n : -1;
    }
  auto at = std::lower_bound(across.begin(), across.end(), FaceAcross{4 * from, 0});
  for (; at != across.end() && at->face < 4 * (from + count); ++at) rows[at->face / 4 - from][at->face % 4] = at->tet;
  return rows;
}

void bulk_columns(const TetBlock& bulk, const SpreadBulk& place, std::vector<std::int32_t>& solid,
                  std::vector<std::int32_t>& piece) {
  // The components again (block_links found them for the links): a linear pass, cheaper than
  // holding 4 bytes per tet of every bulk from the links to the writes.
  std::vector<std::int32_t> label;
  const std::int32_t components = label_tet_regions(
      bulk.neighbours, [](std::size_t) { return true; }, [](std::size_t, int) { return true; }, label);
  if (static_cast<std::size_t>(components) != place.solid.size() ||
      static_cast<std::int64_t>(bulk.tets.size()) != place.tets)
    throw InternalError("the bulk of piece " + std::to_string(place.piece) + " does not match its placement");
  solid.resize(label.size());
  for (std::size_t t = 0; t < label.size(); ++t) solid[t] = place.solid[label[t]];
  piece.assign(bulk.tets.size(), place.piece);
}

Point3 point_of(const SpreadMesh& mesh, std::int64_t id) {
  if (id >= 0 && id < static_cast<std::int64_t>(mesh.split_points.size())) return mesh.split_points[id];
  const std::int64_t healing = id - mesh.first_healing_point;
  if (healing >= 0 && healing < static_cast<std::int64_t>(mesh.healing_points.size()))
    return mesh.healing_points[healing];
  for (const SpreadBulk& bulk : mesh.bulks)
    if (bulk.here && id >= bulk.first_point && id < bulk.first_point + bulk.points)
      return bulk.block.steiner_points.at(id - bulk.first_point);
  // The pieces' Steiner points the band uses: the first ids of its table.
  const auto steiner_end = mesh.band_point_ids.begin() + static_cast<std::ptrdiff_t>(mesh.band_steiner_points.size());
  const auto at = std::lower_bound(mesh.band_point_ids.begin(), steiner_end, id);
  if (at == steiner_end || *at != id) throw InternalError("point " + std::to_string(id) + " is not kept on rank 0");
  return mesh.band_steiner_points[at - mesh.band_point_ids.begin()];
}

std::vector<int> piece_values(const SpreadMesh& mesh) {
  std::vector<int> values;
  for (const SpreadBulk& bulk : mesh.bulks)
    if (bulk.tets > 0) values.push_back(bulk.piece);
  values.insert(values.end(), mesh.band_piece.begin(), mesh.band_piece.end());
  std::sort(values.begin(), values.end());
  values.erase(std::unique(values.begin(), values.end()), values.end());
  return values;
}

void band_tets_of(const SpreadMesh& mesh, int piece, std::vector<GlobalTet>& tets, std::vector<std::int32_t>& solid,
                  std::vector<std::int64_t>* rows) {
  tets.clear(), solid.clear();
  if (rows) rows->clear();
  const PointIds ids = mesh.band_ids();
  for (std::size_t t = 0; t < mesh.band_tets.size(); ++t) {
    if (mesh.band_piece[t] != piece) continue;
    tets.push_back(ids(mesh.band_tets[t])), solid.push_back(mesh.band_solid[t]);
    if (rows) rows->push_back(mesh.first_band_tet + static_cast<std::int64_t>(t));
  }
}

Bounds bounds_of_rows(const SpreadMesh& mesh, const std::function<Bounds(const SpreadBulk&)>& elsewhere) {
  Bounds all;
  bool any = false;
  const auto add = [&](const Bounds& b) {
    for (int c = 0; c < 3; ++c) {
      all.min[c] = any ? std::min(all.min[c], b.min[c]) : b.min[c];
      all.max[c] = any ? std::max(all.max[c], b.max[c]) : b.max[c];
    }
    any = true;
  };
  if (!mesh.split_points.empty()) add(bounds_of(mesh.split_points));
  if (!mesh.healing_points.empty()) add(bounds_of(mesh.healing_points));
  for (const SpreadBulk& bulk : mesh.bulks)
    if (bulk.points > 0) add(bulk.here ? bounds_of(bulk.block.steiner_points) : elsewhere(bulk));
  return all;
}

}  // namespace partet
