#include "partet/piece.hpp"

#include <algorithm>
#include <string>

#include "partet/errors.hpp"

namespace partet {

std::vector<PieceSurface> assemble_pieces(const SplitSurface& split, const std::vector<Cap>& caps) {
  const int k = split.piece_count;
  std::vector<std::vector<Triangle>> global_triangles(k);
  for (std::size_t t = 0; t < split.triangles.size(); ++t)
    global_triangles[split.piece[t]].push_back(split.triangles[t]);
  for (const Cap& cap : caps) {
    auto& below = global_triangles[cap.plane];
    auto& above = global_triangles[cap.plane + 1];
    below.insert(below.end(), cap.triangles.begin(), cap.triangles.end());
    for (const auto& t : cap.triangles) above.push_back({t[0], t[2], t[1]});
  }

  std::vector<PieceSurface> pieces(k);
  std::vector<std::int32_t> local(split.points.size(), -1);
  for (int p = 0; p < k; ++p) {
    PieceSurface& piece = pieces[p];
    piece.index = p;
    for (const auto& t : global_triangles[p])
      for (auto v : t) piece.global_ids.push_back(v);
    std::sort(piece.global_ids.begin(), piece.global_ids.end());
    piece.global_ids.erase(std::unique(piece.global_ids.begin(), piece.global_ids.end()),
                           piece.global_ids.end());
    piece.points.reserve(piece.global_ids.size());
    for (std::size_t i = 0; i < piece.global_ids.size(); ++i) {
      local[piece.global_ids[i]] = static_cast<std::int32_t>(i);
      piece.points.push_back(split.points[piece.global_ids[i]]);
    }
    piece.triangles.reserve(global_triangles[p].size());
    for (const auto& t : global_triangles[p]) piece.triangles.push_back({local[t[0]], local[t[1]], local[t[2]]});
    for (auto g : piece.global_ids) local[g] = -1;
    std::vector<Triangle>().swap(global_triangles[p]);
  }
  return pieces;
}

void check_piece_topology(const PieceSurface& piece) {
  // Every directed edge must appear once and its reverse once: closed and consistently oriented.
  std::vector<std::uint64_t> directed;
  directed.reserve(piece.triangles.size() * 3);
  auto key = [](std::int32_t a, std::int32_t b) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
  };
  for (const auto& t : piece.triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
      throw PartitionError("piece " + std::to_string(piece.index) + " has a degenerate triangle");
    for (int e = 0; e < 3; ++e) directed.push_back(key(t[e], t[(e + 1) % 3]));
  }
  std::sort(directed.begin(), directed.end());
  for (std::size_t i = 0; i + 1 < directed.size(); ++i)
    if (directed[i] == directed[i + 1])
      throw PartitionError("piece " + std::to_string(piece.index) +
                           " is not manifold: an edge is used twice in the same direction");
  for (auto d : directed) {
    const auto a = static_cast<std::int32_t>(d >> 32), b = static_cast<std::int32_t>(d & 0xffffffffu);
    if (!std::binary_search(directed.begin(), directed.end(), key(b, a)))
      throw PartitionError("piece " + std::to_string(piece.index) + " is not closed: its surface has a border edge");
  }
}

}  // namespace partet
