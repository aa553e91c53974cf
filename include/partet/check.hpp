// Independent verification of a tet mesh against the surface it should fill.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "partet/mesh_types.hpp"
#include "partet/tetgen_files.hpp"

namespace partet {

struct MeshQuality {
  double amips_avg = 0, amips_max = 0;  // conformal AMIPS energy, 3 = regular tet
  double min_dihedral_deg = 0, max_dihedral_deg = 0;
  std::int64_t below_5deg = 0, above_175deg = 0;  // tets with a dihedral angle < 5 or > 175 deg
};

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

MeshQuality mesh_quality(const TetMesh& mesh);

// Conformal AMIPS energy tr(J^T J) / det(J)^(2/3) of one tet (3 for a regular tet,
// +inf for a flat or inverted one).
double amips_energy(const Point3& a, const Point3& b, const Point3& c, const Point3& d);

}  // namespace partet
