#include "tet_region.hpp"

#include "topology.hpp"

namespace partet {

void add_face_layer(const TetMesh& mesh, std::vector<char>& in_region) {
  std::vector<char> grown = in_region;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    if (in_region[t])
      for (auto nb : mesh.neighbours[t])
        if (nb >= 0) grown[nb] = 1;
  in_region.swap(grown);
}

PieceSurface region_surface(std::vector<Triangle> faces, const TetMesh& mesh, int index,
                            std::vector<std::int32_t>& ids, std::vector<std::int32_t>& scratch) {
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

void replace_region(TetMesh& mesh, const std::vector<char>& in_region, const std::vector<RegionMesh>& parts) {
  std::vector<char> kept(in_region.size());
  for (std::size_t t = 0; t < in_region.size(); ++t) kept[t] = !in_region[t];
  const std::vector<std::int32_t> new_index = compact_ids(kept);
  std::vector<Tet> tets, neighbours;
  std::vector<std::int32_t> piece;
  const bool has_piece = mesh.piece.size() == mesh.tets.size();
  tets.reserve(mesh.tets.size());
  neighbours.reserve(mesh.tets.size());
  std::vector<std::int32_t> seam;  // tets whose faces must be joined: kept ones next to the region, and new ones
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    if (in_region[t]) continue;
    Tet nb;
    bool next_to_region = false;
    for (int j = 0; j < 4; ++j) {
      const auto old = mesh.neighbours[t][j];
      nb[j] = old >= 0 ? new_index[old] : -1;
      next_to_region = next_to_region || (old >= 0 && in_region[old]);
    }
    if (next_to_region) seam.push_back(static_cast<std::int32_t>(tets.size()));
    tets.push_back(mesh.tets[t]);
    neighbours.push_back(nb);
    if (has_piece) piece.push_back(mesh.piece[t]);
  }
  for (const RegionMesh& part : parts) {
    const std::int32_t base = append_local_mesh(part.mesh, part.ids, mesh.points, tets, neighbours);
    for (std::size_t r = 0; r < part.mesh.tets.size(); ++r) seam.push_back(base + static_cast<std::int32_t>(r));
    if (has_piece) piece.resize(tets.size(), -1);  // made by the re-meshing, not by a piece
  }
  connect_open_faces(tets, neighbours, &seam);
  mesh.tets = std::move(tets);
  mesh.neighbours = std::move(neighbours);
  mesh.piece = std::move(piece);
}

std::vector<char> drop_unused_points(TetMesh& mesh) {
  std::vector<char> used = used_vertices(mesh.points.size(), mesh.tets);
  const std::vector<std::int32_t> new_id = compact_ids(used);
  std::vector<Point3> points;
  points.reserve(mesh.points.size());
  for (std::size_t v = 0; v < mesh.points.size(); ++v)
    if (used[v]) points.push_back(mesh.points[v]);
  for (auto& t : mesh.tets)
    for (auto& v : t) v = new_id[v];
  mesh.points = std::move(points);
  return used;
}

}  // namespace partet
