#include "stages/merge.hpp"

#include <algorithm>

#include "partet/errors.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

// The tets with a face that may lie on a cap: three vertices that are not input vertices (no cut
// plane passes through an input vertex). The input's own boundary faces, most of the open faces,
// need no matching.
std::vector<std::int32_t> tets_touching_caps(const TetMesh& mesh, std::int32_t input_vertex_count) {
  std::vector<std::int32_t> touching;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    int on_planes = 0;
    for (auto v : mesh.tets[t]) on_planes += v >= input_vertex_count;
    if (on_planes >= 3) touching.push_back(static_cast<std::int32_t>(t));
  }
  return touching;
}

// Room reserved beyond the welded mesh's size, a fraction of it: seam healing can add tets and
// points, and an array that outgrows its capacity is copied into one twice its size while the old
// one still exists. Reserved pages cost no memory until they are written.
constexpr std::size_t kHealingRoom = 8;  // 1/8

template <class T>
void reserve_with_room(std::vector<T>& array, std::size_t size) {
  array.reserve(size + size / kHealingRoom + 1024);
}

[[noreturn]] void mismatch(int piece, const std::string& what) {
  throw InternalError("the result of piece " + std::to_string(piece) + " " + what);
}

}  // namespace

Welder::Welder(const SplitSurface& split, const std::vector<PieceSurface>& pieces)
    : split_(split),
      pieces_(pieces),
      first_steiner_(static_cast<std::int32_t>(split.points.size())),
      blocks_(pieces.size()) {}

bool Welder::has(int piece) const {
  return piece >= 0 && static_cast<std::size_t>(piece) < blocks_.size() && blocks_[piece].in;
}

void Welder::add(PieceTetMesh&& result) {
  const int p = result.index;
  if (p < 0 || static_cast<std::size_t>(p) >= pieces_.size() || pieces_[p].index != p ||
      result.surface_point_count != static_cast<std::int32_t>(pieces_[p].global_ids.size()))
    mismatch(p, "does not match its piece");
  if (blocks_[p].in) mismatch(p, "arrived twice");
  Block& block = blocks_[p];
  const std::vector<std::int32_t>& global_ids = pieces_[p].global_ids;
  const std::int32_t surface_count = result.surface_point_count;
  block.tets = std::move(result.mesh.tets);
  for (Tet& t : block.tets)
    for (auto& v : t) v = v < surface_count ? global_ids[v] : first_steiner_ + (v - surface_count);
  block.neighbours = std::move(result.mesh.neighbours);
  block.steiner_points = std::move(result.mesh.steiner_points);
  block.in = true;
  result.mesh = LocalTetMesh();
}

PieceTetMesh Welder::take_back(int p) {
  if (!has(p)) mismatch(p, "was never welded");
  Block& block = blocks_[p];
  const std::vector<std::int32_t>& global_ids = pieces_[p].global_ids;
  const auto surface_count = static_cast<std::int32_t>(global_ids.size());
  PieceTetMesh result;
  result.index = p;
  result.surface_point_count = surface_count;
  result.mesh.tets = std::move(block.tets);
  for (Tet& t : result.mesh.tets)
    for (auto& v : t)
      v = v < first_steiner_ ? static_cast<std::int32_t>(std::lower_bound(global_ids.begin(), global_ids.end(), v) -
                                                         global_ids.begin())
                             : surface_count + (v - first_steiner_);
  result.mesh.neighbours = std::move(block.neighbours);
  result.mesh.steiner_points = std::move(block.steiner_points);
  block = Block();
  return result;
}

TetMesh Welder::finish(std::vector<Point3> split_points) {
  if (split_points.size() != static_cast<std::size_t>(first_steiner_))
    throw InternalError("the welder was given " + std::to_string(split_points.size()) + " split points, not " +
                        std::to_string(first_steiner_));
  std::size_t tet_total = 0, steiner_total = 0;
  for (std::size_t p = 0; p < blocks_.size(); ++p) {
    if (!blocks_[p].in) mismatch(static_cast<int>(p), "is missing");
    tet_total += blocks_[p].tets.size();
    steiner_total += blocks_[p].steiner_points.size();
  }
  if (tet_total > static_cast<std::size_t>(INT32_MAX) || split_points.size() + steiner_total > INT32_MAX)
    throw MeshingError(FailureKind::other, -1,
                       "the merged mesh has more than 2^31 tetrahedra or points; this version numbers them with int32");
  TetMesh mesh;
  mesh.points = std::move(split_points);
  // The split reserved room (split_at_planes), so this copies every point only when that room
  // cannot take the Steiner points and what healing adds (reserve keeps a large enough array).
  reserve_with_room(mesh.points, mesh.points.size() + steiner_total);
  reserve_with_room(mesh.tets, tet_total);
  reserve_with_room(mesh.neighbours, tet_total);
  reserve_with_room(mesh.piece, tet_total);
  for (std::size_t p = 0; p < blocks_.size(); ++p) {
    Block& block = blocks_[p];
    // Earlier pieces' Steiner points come first; tets follow each other in piece order.
    const auto steiner_shift = static_cast<std::int32_t>(mesh.points.size()) - first_steiner_;
    const auto tet_base = static_cast<std::int32_t>(mesh.tets.size());
    mesh.points.insert(mesh.points.end(), block.steiner_points.begin(), block.steiner_points.end());
    for (Tet t : block.tets) {
      for (auto& v : t)
        if (v >= first_steiner_) v += steiner_shift;
      mesh.tets.push_back(t);
    }
    for (Tet nb : block.neighbours) {
      for (auto& n : nb)
        if (n >= 0) n += tet_base;
      mesh.neighbours.push_back(nb);
    }
    mesh.piece.resize(mesh.tets.size(), pieces_[p].index);
    block = Block();  // welded: free it now
  }
  // A cap face is open in the two pieces it separates.
  const std::vector<std::int32_t> touching = tets_touching_caps(mesh, split_.input_vertex_count);
  connect_open_faces(mesh.tets, mesh.neighbours, &touching);
  return mesh;
}

TetMesh weld(const SplitSurface& split, const std::vector<PieceSurface>& pieces, std::vector<PieceTetMesh>&& results) {
  Welder welder(split, pieces);
  for (auto& result : results) welder.add(std::move(result));
  return welder.finish(split.points);
}

}  // namespace partet
