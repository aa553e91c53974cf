#include "stages/tet_region.hpp"

#include <algorithm>

#include "stages/topology.hpp"

namespace partet {

PieceSurface region_surface(std::vector<Triangle> faces, const TetMesh& mesh, int index, std::vector<std::int32_t>& ids) {
  PieceSurface region;
  region.index = index;
  region.seam_region = true;
  ids = renumber_locally(faces);
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

// Opens the faces of the kept tets towards the region (joined again to the new tets later);
// returns the region's slots, ascending, and adds those kept tets to `seam`.
std::vector<std::int32_t> detach_region(TetMesh& mesh, const std::vector<char>& in_region,
                                        std::vector<std::int32_t>& seam) {
  std::vector<std::int32_t> freed;
  for (std::size_t t = 0; t < in_region.size(); ++t) {
    if (!in_region[t]) continue;
    freed.push_back(static_cast<std::int32_t>(t));
    for (auto nb : mesh.neighbours[t])
      if (nb >= 0 && !in_region[nb]) {
        for (auto& back : mesh.neighbours[nb])
          if (back == static_cast<std::int32_t>(t)) back = -1;
        seam.push_back(nb);
      }
  }
  return freed;
}

// Moves tet `from` to slot `to`, and its neighbours' references with it.
void move_tet(TetMesh& mesh, std::int32_t from, std::int32_t to) {
  mesh.tets[to] = mesh.tets[from];
  mesh.neighbours[to] = mesh.neighbours[from];
  if (!mesh.piece.empty()) mesh.piece[to] = mesh.piece[from];
  for (auto nb : mesh.neighbours[to])
    if (nb >= 0)
      for (auto& back : mesh.neighbours[nb])
        if (back == from) back = to;
}

void resize_tets(TetMesh& mesh, std::size_t size) {
  mesh.tets.resize(size);
  mesh.neighbours.resize(size);
  if (!mesh.piece.empty()) mesh.piece.resize(size);
}

// Fills the slots freed[first..] (ascending, vacant) with the last kept tets, so the arrays stay
// dense; returns the moves (from, to). Works on the slot lists, not on a mark per tet.
std::vector<std::pair<std::int32_t, std::int32_t>> fill_vacant_slots(TetMesh& mesh, const std::vector<std::int32_t>& freed,
                                                                     std::size_t first) {
  std::vector<std::pair<std::int32_t, std::int32_t>> moved;
  std::size_t size = mesh.tets.size(), next = first, vacant_end = freed.size();  // freed[next..vacant_end) vacant
  while (next < vacant_end) {
    if (static_cast<std::size_t>(freed[vacant_end - 1]) + 1 == size) {  // a vacant slot at the end: drop it
      --vacant_end, --size;
      continue;
    }
    const auto from = static_cast<std::int32_t>(size - 1);  // a kept tet
    move_tet(mesh, from, freed[next]);
    moved.emplace_back(from, freed[next++]);
    --size;
  }
  resize_tets(mesh, size);
  return moved;
}

}  // namespace

Replacement replace_region(TetMesh& mesh, const std::vector<char>& in_region, std::vector<RegionMesh> parts) {
  if (mesh.piece.size() != mesh.tets.size()) mesh.piece.clear();
  std::vector<std::int32_t> seam;  // tets whose open faces are joined at the end
  const std::vector<std::int32_t> freed = detach_region(mesh, in_region, seam);
  // 1. The new tets, numbered 0.. over all parts (their Steiner points appended to the mesh).
  std::vector<Tet> tets, neighbours;
  for (RegionMesh& part : parts) {
    append_local_mesh(part.mesh, part.ids, mesh.points, tets, neighbours);
    part = RegionMesh();
  }
  // 2. They take the region's slots, in order, then new ones at the end.
  Replacement where;
  where.new_tets.resize(tets.size());
  const std::size_t end = mesh.tets.size();
  for (std::size_t i = 0; i < tets.size(); ++i)
    where.new_tets[i] = static_cast<std::int32_t>(i < freed.size() ? freed[i] : end + (i - freed.size()));
  if (tets.size() > freed.size()) resize_tets(mesh, end + (tets.size() - freed.size()));
  for (std::size_t i = 0; i < tets.size(); ++i) {
    const std::int32_t slot = where.new_tets[i];
    mesh.tets[slot] = tets[i];
    for (int j = 0; j < 4; ++j)
      mesh.neighbours[slot][j] = neighbours[i][j] >= 0 ? where.new_tets[neighbours[i][j]] : -1;
    if (!mesh.piece.empty()) mesh.piece[slot] = -1;  // made by the re-meshing, not by a piece
  }
  // 3. Region slots left over take the last kept tets. Only kept tets move (the new ones hold
  // the lowest freed slots), each once, from beyond the new end.
  if (tets.size() < freed.size()) where.moved = fill_vacant_slots(mesh, freed, tets.size());
  // 4. Join the new tets to each other's parts and to the kept tets around them (those moved
  // are found at their new slots).
  for (auto& t : seam)
    if (static_cast<std::size_t>(t) >= mesh.tets.size()) {
      const auto it = std::lower_bound(where.moved.begin(), where.moved.end(), t,
                                       [](const auto& move, std::int32_t from) { return move.first > from; });
      t = it->second;
    }
  seam.insert(seam.end(), where.new_tets.begin(), where.new_tets.end());
  std::sort(seam.begin(), seam.end());
  seam.erase(std::unique(seam.begin(), seam.end()), seam.end());
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
