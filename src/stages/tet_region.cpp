#include "stages/tet_region.hpp"

#include "stages/topology.hpp"

namespace partet {

PieceSurface region_surface(std::vector<Triangle> faces, const TetMesh& mesh, int index, std::vector<std::int32_t>& ids,
                            std::vector<std::int32_t>& scratch) {
  PieceSurface region;
  region.index = index;
  region.seam_region = true;
  ids = renumber_locally(faces, scratch);
  region.triangles = std::move(faces);
  region.global_ids = ids;
  region.points.reserve(ids.size());
  for (auto id : ids) region.points.push_back(mesh.points[id]);
  return region;
}

std::vector<std::int32_t> marked_tets(const std::vector<char>& mask) {
  std::vector<std::int32_t> tets;
  for (std::size_t t = 0; t < mask.size(); ++t)
    if (mask[t]) tets.push_back(static_cast<std::int32_t>(t));
  return tets;
}

namespace {

// Opens the faces of the kept tets towards the region (joined again to the new tets later) and
// flags those tets; returns the region's slots, ascending.
std::vector<std::int32_t> detach_region(TetMesh& mesh, const std::vector<char>& in_region, std::vector<char>& on_seam) {
  std::vector<std::int32_t> freed;
  for (std::size_t t = 0; t < in_region.size(); ++t) {
    if (!in_region[t]) continue;
    freed.push_back(static_cast<std::int32_t>(t));
    for (auto nb : mesh.neighbours[t])
      if (nb >= 0 && !in_region[nb]) {
        for (auto& back : mesh.neighbours[nb])
          if (back == static_cast<std::int32_t>(t)) back = -1;
        on_seam[nb] = 1;
      }
  }
  return freed;
}

// Moves tet `from` to slot `to`, and its neighbours' references with it.
void move_tet(TetMesh& mesh, std::vector<char>& on_seam, std::int32_t from, std::int32_t to) {
  mesh.tets[to] = mesh.tets[from];
  mesh.neighbours[to] = mesh.neighbours[from];
  if (!mesh.piece.empty()) mesh.piece[to] = mesh.piece[from];
  on_seam[to] = on_seam[from];
  for (auto nb : mesh.neighbours[to])
    if (nb >= 0)
      for (auto& back : mesh.neighbours[nb])
        if (back == from) back = to;
}

}  // namespace

Replacement replace_region(TetMesh& mesh, const std::vector<char>& in_region, const std::vector<RegionMesh>& parts) {
  if (mesh.piece.size() != mesh.tets.size()) mesh.piece.clear();
  std::vector<char> on_seam(mesh.tets.size(), 0);
  const std::vector<std::int32_t> freed = detach_region(mesh, in_region, on_seam);
  // 1. The new tets, numbered 0.. over all parts (their Steiner points appended to the mesh).
  std::vector<Tet> tets, neighbours;
  for (const RegionMesh& part : parts) append_local_mesh(part.mesh, part.ids, mesh.points, tets, neighbours);
  // 2. They take the region's slots, in order, then new ones at the end.
  Replacement where;
  where.new_tets.resize(tets.size());
  const std::size_t end = mesh.tets.size();
  for (std::size_t i = 0; i < tets.size(); ++i)
    where.new_tets[i] = static_cast<std::int32_t>(i < freed.size() ? freed[i] : end + (i - freed.size()));
  if (tets.size() > freed.size()) {
    const std::size_t size = end + (tets.size() - freed.size());
    mesh.tets.resize(size);
    mesh.neighbours.resize(size);
    if (!mesh.piece.empty()) mesh.piece.resize(size);
    on_seam.resize(size);
  }
  for (std::size_t i = 0; i < tets.size(); ++i) {
    const std::int32_t slot = where.new_tets[i];
    mesh.tets[slot] = tets[i];
    for (int j = 0; j < 4; ++j)
      mesh.neighbours[slot][j] = neighbours[i][j] >= 0 ? where.new_tets[neighbours[i][j]] : -1;
    if (!mesh.piece.empty()) mesh.piece[slot] = -1;  // made by the re-meshing, not by a piece
    on_seam[slot] = 1;
  }
  // 3. Region slots left over take the last kept tets, so the arrays stay dense.
  std::vector<char> vacant(mesh.tets.size(), 0);
  for (std::size_t i = tets.size(); i < freed.size(); ++i) vacant[freed[i]] = 1;
  std::size_t size = mesh.tets.size();
  for (std::size_t i = tets.size(); i < freed.size(); ++i) {
    const std::int32_t to = freed[i];
    while (size > 0 && vacant[size - 1]) --size;
    if (static_cast<std::size_t>(to) >= size) break;
    const auto from = static_cast<std::int32_t>(size - 1);
    move_tet(mesh, on_seam, from, to);
    where.moved.emplace_back(from, to);
    vacant[to] = 0;
    --size;
  }
  while (size > 0 && vacant[size - 1]) --size;
  mesh.tets.resize(size);
  mesh.neighbours.resize(size);
  if (!mesh.piece.empty()) mesh.piece.resize(size);
  on_seam.resize(size);
  // 4. Join the new tets to each other's parts and to the kept tets around them.
  const std::vector<std::int32_t> seam = marked_tets(on_seam);
  connect_open_faces(mesh.tets, mesh.neighbours, &seam);
  return where;
}

std::vector<char> drop_unused_points(TetMesh& mesh) {
  std::vector<char> used = used_vertices(mesh.points.size(), mesh.tets);
  const std::vector<std::int32_t> new_id = compact_ids(used);
  std::size_t kept = 0;  // in place (a point only moves down): no second array of every point
  for (std::size_t v = 0; v < mesh.points.size(); ++v)
    if (used[v]) mesh.points[kept++] = mesh.points[v];
  mesh.points.resize(kept);
  for (auto& t : mesh.tets)
    for (auto& v : t) v = new_id[v];
  return used;
}

}  // namespace partet
