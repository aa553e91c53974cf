// Independent verification of a tet mesh against the surface it should fill.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "partet/mesh_types.hpp"
#include "partet/quality.hpp"
#include "partet/tetgen_files.hpp"

namespace partet {

struct CheckReport {
  std::vector<std::string> violations;  // empty when the mesh is valid
  std::int64_t vertices = 0, tets = 0, boundary_faces = 0;
  double tet_volume = 0, surface_volume = 0;
  long euler_mesh = 0, euler_expected = 0;
  MeshQuality quality;
  bool ok() const { return violations.empty(); }
};

// Checks, without trusting how the mesh was made: every tet positively oriented (exact
// predicate); every triangle in at most two tets; boundary faces (faces in one tet, oriented
// out of it) equal the input triangles, matched through exact vertex coordinates; total tet
// volume equals the volume the input encloses; V-E+F-T equals half the Euler characteristic of
// the input; no duplicate or unused vertices.
CheckReport check_mesh(const SurfaceMesh& input, const TetMesh& mesh);

// check_mesh, and the other files of the set too: .face must be exactly the boundary faces
// (outward, for files partet wrote), .neigh exactly the neighbours the tets imply, and every file
// must carry the same set ID (a set mixed from different runs fails).
CheckReport check_mesh_files(const SurfaceMesh& input, const TetgenFileSet& files);


}  // namespace partet
