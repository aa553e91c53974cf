// Plain interchange types passed between stages: flat arrays, no CGAL or TetGen objects,
// cheap to serialize and to keep in memory.
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

// A tetrahedral mesh. Every tet is positively oriented: orient3d(p0,p1,p2,p3) > 0, i.e.
// det[p1-p0, p2-p0, p3-p0] > 0. neighbours[t][j] is the tet sharing the face opposite
// vertex j, or -1 on the boundary.
struct TetMesh {
  std::vector<Point3> points;
  std::vector<Tet> tets;
  std::vector<Tet> neighbours;
};

// The face of tet t opposite vertex j, oriented so that its normal points out of t.
inline Triangle outward_face(const Tet& t, int j) {
  static constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  return {t[kFace[j][0]], t[kFace[j][1]], t[kFace[j][2]]};
}

}  // namespace partet
