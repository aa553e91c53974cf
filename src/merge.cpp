#include "partet/merge.hpp"

#include <algorithm>
#include <string>

#include "partet/errors.hpp"
#include "partet/face_key.hpp"

namespace partet {
namespace {

struct FaceSlot {
  FaceKey key;
  std::int64_t tet;
  int j;
  bool operator<(const FaceSlot& o) const { return key < o.key || (key == o.key && tet < o.tet); }
};

}  // namespace

std::vector<Tet> compute_neighbours(const std::vector<Tet>& tets) {
  std::vector<FaceSlot> slots;
  slots.reserve(tets.size() * 4);
  for (std::size_t t = 0; t < tets.size(); ++t)
    for (int j = 0; j < 4; ++j)
      slots.push_back({FaceKey(outward_face(tets[t], j)), static_cast<std::int64_t>(t), j});
  std::sort(slots.begin(), slots.end());
  std::vector<Tet> neighbours(tets.size(), Tet{-1, -1, -1, -1});
  for (std::size_t i = 0; i < slots.size();) {
    std::size_t e = i + 1;
    while (e < slots.size() && slots[e].key == slots[i].key) ++e;
    if (e - i > 2) throw MeshingError(-1, "a triangle is shared by more than two tetrahedra after merging");
    if (e - i == 2) {
      neighbours[slots[i].tet][slots[i].j] = static_cast<std::int32_t>(slots[i + 1].tet);
      neighbours[slots[i + 1].tet][slots[i + 1].j] = static_cast<std::int32_t>(slots[i].tet);
    }
    i = e;
  }
  return neighbours;
}

TetMesh weld(const std::vector<Point3>& surface_points, const std::vector<PieceSurface>& pieces,
             const std::vector<PieceTetMesh>& results) {
  return weld(surface_points, pieces, std::vector<PieceTetMesh>(results));
}

TetMesh weld(const std::vector<Point3>& surface_points, const std::vector<PieceSurface>& pieces,
             std::vector<PieceTetMesh>&& results) {
  TetMesh mesh;
  mesh.points = surface_points;
  std::size_t tet_total = 0;
  for (const auto& r : results) tet_total += r.mesh.tets.size();
  if (tet_total > static_cast<std::size_t>(INT32_MAX))
    throw MeshingError(-1, "the merged mesh has more than 2^31 tetrahedra; this version numbers tets with int32");
  mesh.tets.reserve(tet_total);
  mesh.neighbours.reserve(tet_total);

  std::vector<FaceSlot> open_faces;  // faces on a piece's boundary: input or cap triangles
  for (std::size_t p = 0; p < results.size(); ++p) {
    PieceTetMesh& r = results[p];
    const PieceSurface& piece = pieces[p];
    if (r.index != piece.index) throw MeshingError(r.index, "result does not match its piece");
    const auto steiner_base = static_cast<std::int64_t>(mesh.points.size()) - r.surface_point_count;
    mesh.points.insert(mesh.points.end(), r.mesh.steiner_points.begin(), r.mesh.steiner_points.end());
    const auto tet_base = static_cast<std::int32_t>(mesh.tets.size());
    for (std::size_t t = 0; t < r.mesh.tets.size(); ++t) {
      Tet g, nb;
      for (int j = 0; j < 4; ++j) {
        const auto v = r.mesh.tets[t][j];
        g[j] = v < r.surface_point_count ? piece.global_ids[v] : static_cast<std::int32_t>(steiner_base + v);
        nb[j] = r.mesh.neighbours[t][j] >= 0 ? r.mesh.neighbours[t][j] + tet_base : -1;
      }
      mesh.tets.push_back(g);
      mesh.neighbours.push_back(nb);
      for (int j = 0; j < 4; ++j)
        if (nb[j] < 0)
          open_faces.push_back({FaceKey(outward_face(g, j)), static_cast<std::int64_t>(mesh.tets.size() - 1), j});
    }
    results[p].mesh = LocalTetMesh();  // welded: free it now
  }

  // A cap face is open in the two pieces it separates: pair them up.
  std::sort(open_faces.begin(), open_faces.end());
  for (std::size_t i = 0; i < open_faces.size();) {
    std::size_t e = i + 1;
    while (e < open_faces.size() && open_faces[e].key == open_faces[i].key) ++e;
    if (e - i > 2) throw MeshingError(-1, "a cap triangle is shared by more than two pieces");
    if (e - i == 2) {
      mesh.neighbours[open_faces[i].tet][open_faces[i].j] = static_cast<std::int32_t>(open_faces[i + 1].tet);
      mesh.neighbours[open_faces[i + 1].tet][open_faces[i + 1].j] = static_cast<std::int32_t>(open_faces[i].tet);
    }
    i = e;
  }
  return mesh;
}

}  // namespace partet
