#include "stages/piece.hpp"

#include <algorithm>
#include <string>

#include "partet/errors.hpp"
#include "stages/topology.hpp"

namespace partet {

PieceAssembler::PieceAssembler(const SplitSurface& split) : split_(split), input_part_(split.piece_count) {
  std::vector<std::size_t> count(input_part_.size(), 0);  // exact sizes: no array grows past its need
  for (auto p : split.piece) ++count[p];
  for (std::size_t p = 0; p < count.size(); ++p) input_part_[p].reserve(count[p]);
  for (std::size_t t = 0; t < split.triangles.size(); ++t) input_part_[split.piece[t]].push_back(split.triangles[t]);
}

// Piece p's triangles: its part of the input, the cap below it (reversed), the cap above it.
PieceSurface PieceAssembler::assemble(int p, const Cap* below, const Cap* above) {
  PieceSurface piece;
  piece.index = p;
  piece.triangles = std::move(input_part_[p]);
  if (below)
    for (const auto& t : below->triangles) piece.triangles.push_back({t[0], t[2], t[1]});
  if (above) piece.triangles.insert(piece.triangles.end(), above->triangles.begin(), above->triangles.end());
  scratch_.resize(split_.points.size(), -1);  // caps built since the last piece added points
  piece.global_ids = renumber_locally(piece.triangles, scratch_);
  piece.points.reserve(piece.global_ids.size());
  for (auto g : piece.global_ids) piece.points.push_back(split_.points[g]);
  return piece;
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
