#include "partet/piece.hpp"

#include <algorithm>
#include <string>

#include "partet/errors.hpp"
#include "topology.hpp"

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
  std::vector<std::int32_t> scratch(split.points.size(), -1);
  for (int p = 0; p < k; ++p) {
    PieceSurface& piece = pieces[p];
    piece.index = p;
    piece.triangles = std::move(global_triangles[p]);
    piece.global_ids = renumber_locally(piece.triangles, scratch);
    piece.points.reserve(piece.global_ids.size());
    for (auto g : piece.global_ids) piece.points.push_back(split.points[g]);
  }
  return pieces;
}

void check_piece_topology(const PieceSurface& piece) {
  const auto fail = [&](const std::string& what) { throw MeshingError(FailureKind::bad_surface, piece.index, what); };
  // Every directed edge must appear once and its reverse once: closed and consistently oriented.
  std::vector<std::uint64_t> directed;
  directed.reserve(piece.triangles.size() * 3);
  auto key = [](std::int32_t a, std::int32_t b) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
  };
  for (const auto& t : piece.triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) fail("its surface has a degenerate triangle");
    for (int e = 0; e < 3; ++e) directed.push_back(key(t[e], t[(e + 1) % 3]));
  }
  std::sort(directed.begin(), directed.end());
  for (std::size_t i = 0; i + 1 < directed.size(); ++i)
    if (directed[i] == directed[i + 1])
      fail("its surface is not manifold: an edge is used twice in the same direction");
  for (auto d : directed) {
    const auto a = static_cast<std::int32_t>(d >> 32), b = static_cast<std::int32_t>(d & 0xffffffffu);
    if (!std::binary_search(directed.begin(), directed.end(), key(b, a)))
      fail("its surface is not closed: it has a border edge");
  }
}

}  // namespace partet
