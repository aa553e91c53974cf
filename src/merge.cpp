#include "partet/merge.hpp"

#include "partet/errors.hpp"
#include "topology.hpp"

namespace partet {

TetMesh weld(const std::vector<Point3>& surface_points, const std::vector<PieceSurface>& pieces,
             std::vector<PieceTetMesh>&& results) {
  TetMesh mesh;
  mesh.points = surface_points;
  std::size_t tet_total = 0;
  for (const auto& r : results) tet_total += r.mesh.tets.size();
  if (tet_total > static_cast<std::size_t>(INT32_MAX))
    throw MeshingError(FailureKind::other, -1,
                       "the merged mesh has more than 2^31 tetrahedra; this version numbers tets with int32");
  mesh.tets.reserve(tet_total);
  mesh.neighbours.reserve(tet_total);
  mesh.piece.reserve(tet_total);
  for (std::size_t p = 0; p < results.size(); ++p) {
    if (results[p].index != pieces[p].index ||
        results[p].surface_point_count != std::int32_t(pieces[p].global_ids.size()))
      throw InternalError("the result of piece " + std::to_string(results[p].index) + " does not match its piece");
    append_local_mesh(results[p].mesh, pieces[p].global_ids, mesh.points, mesh.tets, mesh.neighbours);
    mesh.piece.resize(mesh.tets.size(), pieces[p].index);
    results[p].mesh = LocalTetMesh();  // welded: free it now
  }
  // A cap face is open in the two pieces it separates.
  connect_open_faces(mesh.tets, mesh.neighbours);
  return mesh;
}

}  // namespace partet
