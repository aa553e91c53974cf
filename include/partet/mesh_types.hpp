// Plain interchange types passed between stages: flat arrays, no CGAL or TetGen objects,
// cheap to serialize and to keep in memory.
//
// Conventions for every tet mesh in partet:
// - a tet (p0, p1, p2, p3) is positively oriented: det[p1-p0, p2-p0, p3-p0] > 0;
// - face j of a tet is the face opposite its vertex j; outward_face(t, j) lists it with its
//   normal pointing out of the tet;
// - neighbours[t][j] is the tet across face j, or -1 where face j is on the boundary.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

namespace partet {

using Point3 = std::array<double, 3>;
using Triangle = std::array<std::int32_t, 3>;
using Tet = std::array<std::int32_t, 4>;

// A closed triangle surface. Triangles are oriented with normals pointing out of the solid
// (for a cavity shell: into the void).
struct SurfaceMesh {
  std::vector<Point3> points;
  std::vector<Triangle> triangles;
};

// A tetrahedral mesh (see the conventions above).
struct TetMesh {
  std::vector<Point3> points;
  std::vector<Tet> tets;
  std::vector<Tet> neighbours;
  // Optional (empty, or one entry per tet): the piece whose TetGen run made the tet; -1 for the
  // tets re-meshed after the merge (around the cuts, or by the polish).
  std::vector<std::int32_t> piece;
};

// The face of tet t opposite vertex j, oriented so that its normal points out of t.
inline Triangle outward_face(const Tet& t, int j) {
  static constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  return {t[kFace[j][0]], t[kFace[j][1]], t[kFace[j][2]]};
}

// A tet mesh of a closed surface, numbered locally: points [0, surface point count) are the
// surface's points in the same order; later points are interior Steiner points, listed here.
struct LocalTetMesh {
  std::vector<Point3> steiner_points;
  std::vector<Tet> tets;
  std::vector<Tet> neighbours;  // -1 where the face is on the surface
};

// A piece's tet mesh as sent back to rank 0.
struct PieceTetMesh {
  int index = 0;
  std::int32_t surface_point_count = 0;  // local ids below this map through the piece's global_ids
  LocalTetMesh mesh;
};

}  // namespace partet
