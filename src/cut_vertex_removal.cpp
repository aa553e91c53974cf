#include "partet/cut_vertex_removal.hpp"

#include <algorithm>
#include <unordered_map>

#include "partet/errors.hpp"
#include "partet/face_key.hpp"
#include "partet/merge.hpp"

namespace partet {

CutVertexRemovalStats remove_cut_vertices(TetMesh& mesh, const SurfaceMesh& input, const SplitSurface& split,
                                          const TetgenOptions& options) {
  CutVertexRemovalStats stats;
  const std::int32_t first_cut = split.input_vertex_count;
  const std::int32_t end_cut = first_cut + split.cut_vertex_count();
  auto is_cut = [&](std::int32_t v) { return v >= first_cut && v < end_cut; };

  // The region to re-mesh: every tet touching a cut vertex.
  std::vector<char> in_region(mesh.tets.size(), 0);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    for (auto v : mesh.tets[t])
      if (is_cut(v)) in_region[t] = 1;

  std::unordered_map<FaceKey, std::int32_t, FaceKeyHash> fragment_parent;
  for (std::size_t t = 0; t < split.triangles.size(); ++t)
    for (auto v : split.triangles[t])
      if (split.is_cut_vertex(v)) {
        fragment_parent.emplace(FaceKey(split.triangles[t]), split.parent[t]);
        break;
      }

  // A part TetGen cannot re-mesh without touching its boundary (its faces are those of the
  // existing, often flat, tets around it) gets a layer of neighbouring tets added and is tried
  // again: the larger the part, the closer the job gets to meshing the input triangles alone.
  constexpr int kMaxGrowth = 3;
  std::vector<std::int32_t> component(mesh.tets.size(), -1);
  std::int32_t component_count = 0;
  std::vector<std::vector<std::int32_t>> part_ids;
  std::vector<LocalTetMesh> part_mesh;
  for (int growth = 0;; ++growth) {
    // The region falls into connected parts (one per cut loop, or per group of loops that share
    // tets). Each part is re-meshed on its own: smaller TetGen runs, and a failure names the cut
    // planes involved so only those planes need to move.
    std::fill(component.begin(), component.end(), -1);
    component_count = 0;
    std::vector<std::size_t> stack;
    for (std::size_t seed = 0; seed < mesh.tets.size(); ++seed) {
      if (!in_region[seed] || component[seed] >= 0) continue;
      component[seed] = component_count;
      stack.push_back(seed);
      while (!stack.empty()) {
        const std::size_t t = stack.back();
        stack.pop_back();
        for (auto nb : mesh.neighbours[t])
          if (nb >= 0 && in_region[nb] && component[nb] < 0) {
            component[nb] = component_count;
            stack.push_back(static_cast<std::size_t>(nb));
          }
      }
      ++component_count;
    }

    // Each part's boundary: faces towards tets outside the region, and mesh-boundary faces
    // without a cut vertex. Mesh-boundary faces with a cut vertex are fragments of split input
    // triangles; the input triangles themselves replace them (all fragments of a triangle share
    // cut vertices, so they lie in one part).
    std::vector<std::vector<Triangle>> part_faces(component_count);
    std::vector<std::vector<std::int32_t>> part_parents(component_count);
    std::vector<std::vector<int>> part_planes(component_count);
    for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
      if (!in_region[t]) continue;
      const auto c = component[t];
      for (auto v : mesh.tets[t])
        if (is_cut(v)) part_planes[c].push_back(split.cut_vertex_plane[v - first_cut]);
      for (int j = 0; j < 4; ++j) {
        const auto nb = mesh.neighbours[t][j];
        if (nb >= 0 && in_region[nb]) continue;
        const Triangle face = outward_face(mesh.tets[t], j);
        if (nb < 0 && (is_cut(face[0]) || is_cut(face[1]) || is_cut(face[2]))) {
          auto it = fragment_parent.find(FaceKey(face));
          if (it == fragment_parent.end())
            throw MeshingError(-1, "cut-vertex removal: a boundary face with a cut vertex is no fragment of an input triangle");
          part_parents[c].push_back(it->second);
          continue;
        }
        part_faces[c].push_back(face);
      }
    }

    part_ids.assign(component_count, {});
    part_mesh.assign(component_count, LocalTetMesh());
    std::int32_t failed = -1;
    std::string failure;
    for (std::int32_t c = 0; c < component_count && failed < 0; ++c) {
      auto& parents = part_parents[c];
      std::sort(parents.begin(), parents.end());
      parents.erase(std::unique(parents.begin(), parents.end()), parents.end());
      for (auto f : parents) part_faces[c].push_back(input.triangles[f]);
      auto& planes = part_planes[c];
      std::sort(planes.begin(), planes.end());
      planes.erase(std::unique(planes.begin(), planes.end()), planes.end());

      std::vector<Triangle>& faces = part_faces[c];
      std::vector<std::int32_t>& ids = part_ids[c];
      for (const auto& f : faces) ids.insert(ids.end(), f.begin(), f.end());
      std::sort(ids.begin(), ids.end());
      ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
      std::vector<Point3> local_points(ids.size());
      for (std::size_t i = 0; i < ids.size(); ++i) local_points[i] = mesh.points[ids[i]];
      for (auto& f : faces)
        for (auto& v : f)
          v = static_cast<std::int32_t>(std::lower_bound(ids.begin(), ids.end(), v) - ids.begin());
      try {
        part_mesh[c] = mesh_closed_surface(local_points, faces, options);
      } catch (const MeshingError& e) {
        failed = c;
        failure = e.what();
      }
    }
    if (failed < 0) break;
    if (growth == kMaxGrowth) {
      std::string planes;
      for (int p : part_planes[failed]) planes += (planes.empty() ? "" : ", ") + std::to_string(p);
      throw CutRemovalError("cut-vertex removal near cut plane(s) " + planes + ": " + failure, part_planes[failed]);
    }
    // Grow the failing part by the tets sharing a vertex with it.
    std::vector<char> touched(mesh.points.size(), 0);
    for (std::size_t t = 0; t < mesh.tets.size(); ++t)
      if (component[t] == failed)
        for (auto v : mesh.tets[t]) touched[v] = 1;
    for (std::size_t t = 0; t < mesh.tets.size(); ++t)
      if (!in_region[t])
        for (auto v : mesh.tets[t])
          if (touched[v]) in_region[t] = 1;
  }

  // Tets outside the region keep their order and their neighbours among themselves; faces they
  // share with the region are matched to the new tets below.
  std::vector<Tet> tets, neighbours;
  tets.reserve(mesh.tets.size());
  neighbours.reserve(mesh.tets.size());
  std::vector<std::int32_t> new_index(mesh.tets.size(), -1);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    if (in_region[t]) {
      ++stats.cavity_tets_in;
      continue;
    }
    new_index[t] = static_cast<std::int32_t>(tets.size());
    tets.push_back(mesh.tets[t]);
  }
  std::unordered_map<FaceKey, std::pair<std::int32_t, int>, FaceKeyHash> open_towards_region;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    if (in_region[t]) continue;
    Tet nb;
    for (int j = 0; j < 4; ++j) {
      const auto old = mesh.neighbours[t][j];
      nb[j] = old >= 0 ? new_index[old] : -1;
      if (old >= 0 && in_region[old])
        open_towards_region.emplace(FaceKey(outward_face(mesh.tets[t], j)), std::make_pair(new_index[t], j));
    }
    neighbours.push_back(nb);
  }

  for (std::int32_t c = 0; c < component_count; ++c) {
    const std::vector<std::int32_t>& ids = part_ids[c];
    const LocalTetMesh& region = part_mesh[c];
    const auto steiner_base = static_cast<std::int64_t>(mesh.points.size()) - static_cast<std::int64_t>(ids.size());
    mesh.points.insert(mesh.points.end(), region.steiner_points.begin(), region.steiner_points.end());
    const auto base = static_cast<std::int32_t>(tets.size());
    for (std::size_t r = 0; r < region.tets.size(); ++r) {
      const Tet& t = region.tets[r];
      Tet g, nb;
      for (int j = 0; j < 4; ++j)
        g[j] = t[j] < static_cast<std::int32_t>(ids.size()) ? ids[t[j]]
                                                             : static_cast<std::int32_t>(steiner_base + t[j]);
      for (int j = 0; j < 4; ++j) {
        nb[j] = region.neighbours[r][j] >= 0 ? base + region.neighbours[r][j] : -1;
        if (nb[j] >= 0) continue;
        auto it = open_towards_region.find(FaceKey(outward_face(g, j)));
        if (it == open_towards_region.end()) continue;  // on the mesh boundary
        nb[j] = it->second.first;
        neighbours[it->second.first][it->second.second] = base + static_cast<std::int32_t>(r);
      }
      tets.push_back(g);
      neighbours.push_back(nb);
    }
    stats.cavity_tets_out += static_cast<std::int64_t>(region.tets.size());
  }

  // Drop unused points (the cut vertices, and input vertices no triangle uses), keeping order.
  std::vector<std::int32_t> new_id(mesh.points.size(), -1);
  for (const auto& t : tets)
    for (auto v : t) new_id[v] = 0;
  std::vector<Point3> points;
  points.reserve(mesh.points.size());
  for (std::size_t v = 0; v < mesh.points.size(); ++v) {
    if (new_id[v] < 0) {
      if (is_cut(static_cast<std::int32_t>(v))) ++stats.removed;
      continue;
    }
    new_id[v] = static_cast<std::int32_t>(points.size());
    points.push_back(mesh.points[v]);
  }
  for (auto& t : tets)
    for (auto& v : t) {
      if (is_cut(v)) throw MeshingError(-1, "cut-vertex removal left a cut vertex in the mesh");
      v = new_id[v];
    }
  mesh.points = std::move(points);
  mesh.neighbours = std::move(neighbours);
  mesh.tets = std::move(tets);
  return stats;
}

}  // namespace partet
