// A two-tet mesh for the writers' unit tests.
#pragma once
#include <vector>

#include "io/mesh_formats.hpp"

namespace partet::test {

// Two tets sharing face (1,2,3), one meshed by piece 0 and one re-meshed at a seam (-1), with
// their five outer faces as the boundary (the last one a part of a split input triangle).
struct TwoTets {
  TetMesh mesh;
  std::vector<Triangle> boundary;
  TwoTets() {
    mesh.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
    mesh.tets = {{0, 1, 2, 3}, {1, 4, 2, 3}};
    mesh.piece = {0, -1};
    boundary = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 4}, {1, 4, 3}, {2, 3, 4}};
  }
  MeshOutput output() const { return MeshOutput{mesh, boundary, 5}; }
};

}  // namespace partet::test
