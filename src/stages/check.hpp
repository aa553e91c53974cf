// Independent verification of a tet mesh against the surface it should fill.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "partet/mesh_types.hpp"
#include "stages/quality.hpp"
#include "io/tetgen_files.hpp"

namespace partet {

// What the boundary of a mesh must be.
enum class BoundaryRule {
  exact,  // exactly the input triangles
  // The input triangles, some of them split into parts (a mesh made with --allow-split-faces):
  // the boundary faces that are not input triangles must tile, facing the same way, the input
  // triangles that are not boundary faces. Points TetGen put on the surface were rounded, so
  // "on the triangle" allows 1e-9 of the input's size.
  split_allowed,
};

struct CheckReport {
  std::vector<std::string> violations;  // empty when the mesh is valid
  std::int64_t vertices = 0, tets = 0, boundary_faces = 0;
  std::int64_t split_input_faces = 0;  // input triangles tiled by parts (BoundaryRule::split_allowed)
  double tet_volume = 0, surface_volume = 0;
  long euler_mesh = 0, euler_expected = 0;
  MeshQuality quality;
  std::optional<ZoneQuality> zones;  // the seam zone's and the rest's, when the check found them
  bool ok() const { return violations.empty(); }
};

// Checks, without trusting how the mesh was made: every tet positively oriented (exact
// predicate); every triangle in at most two tets; boundary faces (faces in one tet, oriented
// out of it) equal the input triangles, matched through exact vertex coordinates; total tet
// volume equals the volume the input encloses; V-E+F-T equals half the Euler characteristic of
// the input; no duplicate or unused vertices.
CheckReport check_mesh(const SurfaceMesh& input, const TetMesh& mesh, BoundaryRule rule = BoundaryRule::exact);

// The check's own geometry, for the distributed check of an XDMF set (partet check under mpirun):
// the exact orientation of tet (a, b, c, d) (1 positive, 0 flat, -1 inverted); six times its
// signed volume in long double (no underflow at any input's scale); the Euler characteristic
// V - E + F of a surface, counting vertices in triangles only.
int tet_orientation(const Point3& a, const Point3& b, const Point3& c, const Point3& d);
long double tet_volume6(const Point3& a, const Point3& b, const Point3& c, const Point3& d);
long surface_euler_characteristic(const SurfaceMesh& surface);
// Relative difference allowed between the tets' volume and the volume the input encloses.
inline constexpr double kCheckVolumeTolerance = 1e-9;

// check_mesh, and the other files of the set too: .face must be exactly the boundary faces
// (outward, for files partet wrote), .neigh exactly the neighbours the tets imply, and every file
// must carry the same set ID (a set mixed from different runs fails).
CheckReport check_mesh_files(const SurfaceMesh& input, const TetgenFileSet& files,
                             BoundaryRule rule = BoundaryRule::exact);

// The violation when the files of a set (each with its set ID, as TetgenFileSet::ids) carry
// different IDs; "" when they agree. Also for the check on several ranks.
std::string set_id_violation(const std::vector<std::pair<std::string, std::string>>& ids);


}  // namespace partet
