#include "stages/refine_surface.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/subdivision_method_3.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "partet/errors.hpp"
#include "stages/validate.hpp"
#include "common/memory.hpp"

namespace partet {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
constexpr double kSubdivisionBytesPerFace = 110;

// Only the vertices the triangles use: subdivision cannot handle isolated vertices.
Mesh to_cgal(const SurfaceMesh& surface) {
  std::vector<std::int32_t> id(surface.points.size(), -1);
  for (const Triangle& t : surface.triangles)
    for (auto v : t) id[v] = 0;
  Mesh mesh;
  mesh.reserve(static_cast<Mesh::size_type>(surface.points.size()),
               static_cast<Mesh::size_type>(surface.triangles.size() * 3 / 2),
               static_cast<Mesh::size_type>(surface.triangles.size()));
  for (std::size_t v = 0; v < surface.points.size(); ++v) {
    if (id[v] < 0) continue;
    const Point3& p = surface.points[v];
    id[v] = static_cast<std::int32_t>(mesh.add_vertex(Kernel::Point_3(p[0], p[1], p[2])));
  }
  for (std::size_t f = 0; f < surface.triangles.size(); ++f) {
    const Triangle& t = surface.triangles[f];
    if (mesh.add_face(Mesh::Vertex_index(id[t[0]]), Mesh::Vertex_index(id[t[1]]), Mesh::Vertex_index(id[t[2]])) ==
        Mesh::null_face())
      throw InputError("cannot subdivide: face " + std::to_string(f) + " makes the surface non-manifold");
  }
  return mesh;
}

SurfaceMesh from_cgal(const Mesh& mesh) {
  SurfaceMesh surface;
  surface.points.reserve(mesh.number_of_vertices());
  for (Mesh::Vertex_index v : mesh.vertices()) {
    const auto& p = mesh.point(v);
    surface.points.push_back({p.x(), p.y(), p.z()});
  }
  surface.triangles.reserve(mesh.number_of_faces());
  for (Mesh::Face_index f : mesh.faces()) {
    Triangle t;
    int c = 0;
    for (Mesh::Vertex_index v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
      t[c++] = static_cast<std::int32_t>(v);
    surface.triangles.push_back(t);
  }
  return surface;
}

}  // namespace

void check_subdivision_fits(std::size_t faces, int steps) {
  if (steps < 0) throw OptionError("the number of subdivision steps must be at least 0");
  const long double result = static_cast<long double>(faces) * std::pow(4.0L, steps);
  const std::string what = std::to_string(faces) + " faces x 4^" + std::to_string(steps) + " = " +
                           std::to_string(static_cast<long long>(std::min(result, 1e18L))) + " faces";
  if (result > static_cast<long double>(std::numeric_limits<std::int32_t>::max()))
    throw OptionError("cannot subdivide " + what + ": more than the 2^31 faces a surface can have");
  // Measured: about 100 bytes per face of the result at the peak (armadillo_loop1, 2 steps).
  const double need_mb = static_cast<double>(result) * kSubdivisionBytesPerFace / (1024.0 * 1024.0);
  const double available_mb = available_memory_mb();
  if (available_mb > 0 && need_mb > available_mb)
    throw OptionError("cannot subdivide " + what + ": that needs about " + std::to_string(need_mb / 1024).substr(0, 5) +
                      " GB of memory, and " + std::to_string(available_mb / 1024).substr(0, 5) +
                      " GB are available; use fewer steps");
}

SurfaceMesh loop_subdivide(const SurfaceMesh& surface, int steps) {
  check_subdivision_fits(surface.triangles.size(), steps);
  validate_topology(surface);
  Mesh mesh = to_cgal(surface);
  if (steps > 0) CGAL::Subdivision_method_3::Loop_subdivision(mesh, CGAL::parameters::number_of_iterations(steps));
  return from_cgal(mesh);
}

}  // namespace partet
