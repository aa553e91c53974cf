// What a surface or a tet mesh file holds (partet info).
#include "stages/info.hpp"

#include <algorithm>
#include <numeric>
#include <vector>

#include "stages/geometry.hpp"
#include "partet/errors.hpp"
#include "stages/validate.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {


// Union-find over vertices: shells are the components of the faces.
struct Components {
  std::vector<std::int32_t> parent;
  explicit Components(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::int32_t find(std::int32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  }
  void join(std::int32_t a, std::int32_t b) { parent[find(a)] = find(b); }
};

// Edge counts from the faces' directed edges, sorted by undirected key: border, non-manifold
// and misoriented edges, and the number of distinct edges.
void count_edges(const SurfaceMesh& s, SurfaceInfo& info) {
  struct Directed {
    std::uint64_t key;
    bool forward;  // from the smaller id to the larger
  };
  std::vector<Directed> edges;
  edges.reserve(s.triangles.size() * 3);
  for (const Triangle& t : s.triangles)
    for (int i = 0; i < 3; ++i) {
      const std::int32_t a = t[i], b = t[(i + 1) % 3];
      const auto lo = static_cast<std::uint64_t>(std::min(a, b)), hi = static_cast<std::uint64_t>(std::max(a, b));
      edges.push_back({lo << 32 | hi, a < b});
    }
  std::sort(edges.begin(), edges.end(), [](const Directed& x, const Directed& y) { return x.key < y.key; });
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i, forward = 0;
    for (; j < edges.size() && edges[j].key == edges[i].key; ++j) forward += edges[j].forward;
    const std::size_t count = j - i;
    ++info.edges;
    if (count == 1) ++info.border_edges;
    if (count > 2) ++info.non_manifold_edges;
    if (count == 2 && forward != 1) ++info.misoriented_edges;
    i = j;
  }
}

// Shells and genus: each closed, manifold, oriented shell has V - E + F = 2 - 2g.
void count_shells(const SurfaceMesh& s, const std::vector<char>& used, SurfaceInfo& info) {
  Components components(s.points.size());
  for (const Triangle& t : s.triangles) components.join(t[0], t[1]), components.join(t[1], t[2]);
  for (std::size_t v = 0; v < s.points.size(); ++v)
    if (used[v] && components.find(static_cast<std::int32_t>(v)) == static_cast<std::int32_t>(v)) ++info.shells;
  info.euler = (info.vertices - info.unused_vertices) - info.edges + info.faces;
  if (info.closed() && info.manifold() && info.oriented() && (2 * info.shells - info.euler) % 2 == 0)
    info.genus = (2 * info.shells - info.euler) / 2;
}

}  // namespace

Bounds bounds_of(const std::vector<Point3>& points, const std::vector<char>* used) {
  Bounds b;
  bool first = true;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (used && !(*used)[i]) continue;
    for (int c = 0; c < 3; ++c) {
      b.min[c] = first ? points[i][c] : std::min(b.min[c], points[i][c]);
      b.max[c] = first ? points[i][c] : std::max(b.max[c], points[i][c]);
    }
    first = false;
  }
  return b;
}

SurfaceInfo surface_info(const SurfaceMesh& surface) {
  SurfaceInfo info;
  info.vertices = static_cast<std::int64_t>(surface.points.size());
  info.faces = static_cast<std::int64_t>(surface.triangles.size());
  std::vector<char> used(surface.points.size(), 0);
  for (const Triangle& t : surface.triangles)
    for (std::int32_t v : t) used[v] = 1;
  info.unused_vertices = std::count(used.begin(), used.end(), 0);
  info.bounds = bounds_of(surface.points, &used);
  count_edges(surface, info);
  count_shells(surface, used, info);
  if (info.closed() && info.oriented()) info.volume = enclosed_volume_precise(surface);
  if (info.closed() && info.manifold() && info.oriented()) {
    info.self_intersection_checked = true;
    try {
      check_no_self_intersections(surface, "surface");
    } catch (const InputError& e) {
      info.self_intersection = e.what();
    }
  }
  return info;
}

TetMeshInfo tet_mesh_info(const TetMesh& mesh) {
  TetMeshInfo info;
  info.vertices = static_cast<std::int64_t>(mesh.points.size());
  info.tets = static_cast<std::int64_t>(mesh.tets.size());
  info.bounds = bounds_of(mesh.points);
  const std::vector<Tet> neighbours = mesh.neighbours.size() == mesh.tets.size()
                                          ? mesh.neighbours
                                          : compute_neighbours(mesh.tets, mesh.points.size(), CrowdedFace::leave_open);
  for (const Tet& n : neighbours)
    for (std::int32_t nb : n) info.boundary_faces += nb < 0;
  std::vector<std::int32_t> label;
  info.solids = label_tet_regions(
      neighbours, [](std::size_t) { return true; }, [](std::size_t, int) { return true; }, label);
  for (const Tet& t : mesh.tets) {
    const long double volume =
        tet_volume_precise(mesh.points[t[0]], mesh.points[t[1]], mesh.points[t[2]], mesh.points[t[3]]);
    info.volume += volume;
    info.inverted_tets += volume <= 0;
  }
  info.quality = mesh_quality(mesh);
  return info;
}

}  // namespace partet
