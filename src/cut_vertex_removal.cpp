#include "partet/cut_vertex_removal.hpp"

#include <algorithm>
#include <string>
#include <unordered_map>

#include "partet/errors.hpp"
#include "topology.hpp"

namespace partet {
namespace {

// The cut vertices are the ids [first, end) of the merged mesh.
struct CutRange {
  std::int32_t first, end;
  bool contains(std::int32_t v) const { return v >= first && v < end; }
  bool touches(const Triangle& f) const { return contains(f[0]) || contains(f[1]) || contains(f[2]); }
};

using FragmentParents = std::unordered_map<FaceKey, std::int32_t, FaceKeyHash>;

// Each split fragment of an input triangle (a triangle with a cut vertex), by its input triangle.
FragmentParents fragment_parents(const SplitSurface& split) {
  FragmentParents parent;
  for (std::size_t t = 0; t < split.triangles.size(); ++t)
    for (auto v : split.triangles[t])
      if (split.is_cut_vertex(v)) {
        parent.emplace(FaceKey(split.triangles[t]), split.parent[t]);
        break;
      }
  return parent;
}

// One connected part of the region: the closed surface around it and its new tets.
struct Part {
  std::vector<Triangle> faces;        // its boundary, global ids, then local ids once closed
  std::vector<std::int32_t> parents;  // input triangles replacing its boundary fragments
  std::vector<int> planes;            // cut planes of its cut vertices
  std::vector<std::int32_t> ids;      // local id -> global id
  LocalTetMesh mesh;
};

// Splits the region into connected parts and collects each part's boundary: faces towards tets
// outside the region, and mesh-boundary faces without a cut vertex. Mesh-boundary faces with a
// cut vertex are fragments of split input triangles, recorded by their input triangle (all
// fragments of a triangle share cut vertices, so they lie in one part).
std::vector<Part> region_parts(const TetMesh& mesh, const std::vector<char>& in_region,
                               const std::vector<std::int32_t>& component, std::int32_t component_count,
                               const CutRange& cut, const SplitSurface& split, const FragmentParents& parent_of) {
  std::vector<Part> parts(component_count);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    if (!in_region[t]) continue;
    Part& part = parts[component[t]];
    for (auto v : mesh.tets[t])
      if (cut.contains(v)) part.planes.push_back(split.cut_vertex_plane[v - cut.first]);
    for (int j = 0; j < 4; ++j) {
      const auto nb = mesh.neighbours[t][j];
      if (nb >= 0 && in_region[nb]) continue;
      const Triangle face = outward_face(mesh.tets[t], j);
      if (nb < 0 && cut.touches(face)) {
        auto it = parent_of.find(FaceKey(face));
        if (it == parent_of.end())
          throw InternalError(
              "cut-vertex removal: a boundary face with a cut vertex is no fragment of an input triangle");
        part.parents.push_back(it->second);
        continue;
      }
      part.faces.push_back(face);
    }
  }
  return parts;
}

template <class T>
void sort_unique(std::vector<T>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

// Closes a part's boundary with its input triangles and numbers it locally.
void close_part(Part& part, const SurfaceMesh& input, std::vector<std::int32_t>& scratch) {
  sort_unique(part.parents);
  for (auto f : part.parents) part.faces.push_back(input.triangles[f]);
  sort_unique(part.planes);
  part.ids = renumber_locally(part.faces, scratch);
}

// Meshes every part; returns the first part that failed (-1 if none) and why.
std::int32_t mesh_parts(std::vector<Part>& parts, const TetMesh& mesh, const SurfaceMesh& input,
                        const SurfaceMesher& mesher, Failure& failure) {
  std::vector<std::int32_t> scratch(mesh.points.size(), -1);
  for (std::size_t c = 0; c < parts.size(); ++c) {
    Part& part = parts[c];
    close_part(part, input, scratch);
    std::vector<Point3> local_points(part.ids.size());
    for (std::size_t i = 0; i < part.ids.size(); ++i) local_points[i] = mesh.points[part.ids[i]];
    try {
      part.mesh = mesher(local_points, part.faces);
    } catch (const MeshingError& e) {
      failure = e.failure;
      return static_cast<std::int32_t>(c);
    }
  }
  return -1;
}

// Adds to the region every tet sharing a vertex with the failed part.
void grow_region(const TetMesh& mesh, const std::vector<std::int32_t>& component, std::int32_t failed,
                 std::vector<char>& in_region) {
  std::vector<char> touched(mesh.points.size(), 0);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    if (component[t] == failed)
      for (auto v : mesh.tets[t]) touched[v] = 1;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    if (!in_region[t])
      for (auto v : mesh.tets[t])
        if (touched[v]) in_region[t] = 1;
}

// Replaces the region's tets by the parts' new tets. Tets outside the region keep their order
// and their neighbours among themselves; faces towards the region are joined to the new tets.
void replace_region(TetMesh& mesh, const std::vector<char>& in_region, const std::vector<Part>& parts,
                    CutVertexRemovalStats& stats) {
  std::vector<char> kept(in_region.size());
  for (std::size_t t = 0; t < in_region.size(); ++t) kept[t] = !in_region[t];
  const std::vector<std::int32_t> new_index = compact_ids(kept);
  std::vector<Tet> tets, neighbours;
  std::vector<std::int32_t> piece;
  const bool has_piece = mesh.piece.size() == mesh.tets.size();
  tets.reserve(mesh.tets.size());
  neighbours.reserve(mesh.tets.size());
  std::vector<std::int32_t> seam;  // tets whose faces must be joined: kept ones next to the region, and new ones
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    if (in_region[t]) {
      ++stats.cavity_tets_in;
      continue;
    }
    Tet nb;
    bool next_to_region = false;
    for (int j = 0; j < 4; ++j) {
      const auto old = mesh.neighbours[t][j];
      nb[j] = old >= 0 ? new_index[old] : -1;
      next_to_region = next_to_region || (old >= 0 && in_region[old]);
    }
    if (next_to_region) seam.push_back(static_cast<std::int32_t>(tets.size()));
    tets.push_back(mesh.tets[t]);
    neighbours.push_back(nb);
    if (has_piece) piece.push_back(mesh.piece[t]);
  }
  for (const Part& part : parts) {
    const std::int32_t base = append_local_mesh(part.mesh, part.ids, mesh.points, tets, neighbours);
    for (std::size_t r = 0; r < part.mesh.tets.size(); ++r) seam.push_back(base + static_cast<std::int32_t>(r));
    if (has_piece) piece.resize(tets.size(), -1);  // made by the re-meshing, not by a piece
    stats.cavity_tets_out += static_cast<std::int64_t>(part.mesh.tets.size());
  }
  connect_open_faces(tets, neighbours, &seam);
  mesh.tets = std::move(tets);
  mesh.neighbours = std::move(neighbours);
  mesh.piece = std::move(piece);
}

// Drops unused points (the cut vertices, and input vertices no triangle uses), keeping order.
void drop_unused_points(TetMesh& mesh, const CutRange& cut, CutVertexRemovalStats& stats) {
  const std::vector<char> used = used_vertices(mesh.points.size(), mesh.tets);
  const std::vector<std::int32_t> new_id = compact_ids(used);
  std::vector<Point3> points;
  points.reserve(mesh.points.size());
  for (std::size_t v = 0; v < mesh.points.size(); ++v) {
    if (used[v])
      points.push_back(mesh.points[v]);
    else if (cut.contains(static_cast<std::int32_t>(v)))
      ++stats.removed;
  }
  for (auto& t : mesh.tets)
    for (auto& v : t) {
      if (cut.contains(v)) throw InternalError("cut-vertex removal left a cut vertex in the mesh");
      v = new_id[v];
    }
  mesh.points = std::move(points);
}

}  // namespace

CutVertexRemovalStats remove_cut_vertices(TetMesh& mesh, const SurfaceMesh& input, const SplitSurface& split,
                                          const SurfaceMesher& mesher) {
  CutVertexRemovalStats stats;
  const CutRange cut{split.input_vertex_count, split.input_vertex_count + split.cut_vertex_count()};
  const FragmentParents parent_of = fragment_parents(split);

  // The region to re-mesh: every tet touching a cut vertex.
  std::vector<char> in_region(mesh.tets.size(), 0);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    for (auto v : mesh.tets[t])
      if (cut.contains(v)) in_region[t] = 1;

  // The region falls into connected parts (one per cut loop, or per group of loops that share
  // tets), each re-meshed on its own: smaller TetGen runs, and a failure names the cut planes
  // involved so only those need to move. A part TetGen cannot re-mesh without touching its
  // boundary (the faces of the often flat tets around it) grows by a layer of tets and is
  // tried again: the larger it is, the closer the job gets to meshing the input triangles alone.
  constexpr int kMaxGrowth = 3;
  std::vector<std::int32_t> component;
  std::vector<Part> parts;
  for (int growth = 0;; ++growth) {
    const std::int32_t count = label_tet_regions(
        mesh.neighbours, [&](std::size_t t) { return in_region[t] != 0; }, [](std::size_t, int) { return true; },
        component);
    parts = region_parts(mesh, in_region, component, count, cut, split, parent_of);
    Failure failure;
    const std::int32_t failed = mesh_parts(parts, mesh, input, mesher, failure);
    if (failed < 0) break;
    if (growth == kMaxGrowth) {
      std::string planes;
      for (int p : parts[failed].planes) planes += (planes.empty() ? "" : ", ") + std::to_string(p);
      failure.message = "cut-vertex removal near cut plane(s) " + planes + ": " + failure.text();
      failure.piece = -1;
      failure.planes = parts[failed].planes;
      throw MeshingError(failure);
    }
    grow_region(mesh, component, failed, in_region);
  }
  replace_region(mesh, in_region, parts, stats);
  drop_unused_points(mesh, cut, stats);
  return stats;
}

}  // namespace partet
