#include "partet/seam_healing.hpp"

#include <algorithm>
#include <string>
#include <map>
#include <unordered_map>

#include "partet/errors.hpp"
#include "topology.hpp"

namespace partet {
namespace {

// The vertices to remove: the cut vertices [first, first_cap) and, when healing, the caps'
// interior points [first_cap, end), ids of the merged mesh.
struct Removed {
  std::int32_t first, first_cap, end;
  const SplitSurface& split;
  bool contains(std::int32_t v) const { return v >= first && v < end; }
  bool is_cut_vertex(std::int32_t v) const { return v >= first && v < first_cap; }
  bool touches(const Triangle& f) const { return is_cut_vertex(f[0]) || is_cut_vertex(f[1]) || is_cut_vertex(f[2]); }
  int plane_of(std::int32_t v) const {
    return v < first_cap ? split.cut_vertex_plane[v - first] : split.cap_point_plane[v - first_cap];
  }
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
                               const Removed& removed, const FragmentParents& parent_of) {
  std::vector<Part> parts(component_count);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    if (!in_region[t]) continue;
    Part& part = parts[component[t]];
    for (auto v : mesh.tets[t])
      if (removed.contains(v)) part.planes.push_back(removed.plane_of(v));
    for (int j = 0; j < 4; ++j) {
      const auto nb = mesh.neighbours[t][j];
      if (nb >= 0 && in_region[nb]) continue;
      const Triangle face = outward_face(mesh.tets[t], j);
      if (nb < 0 && removed.touches(face)) {
        auto it = parent_of.find(FaceKey(face));
        if (it == parent_of.end())
          throw InternalError(
              "seam healing: a boundary face with a cut vertex is no fragment of an input triangle");
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

// Re-meshed regions by content: after a region grows, the regions it did not touch come back
// unchanged and need no new TetGen run.
class RegionCache {
 public:
  const LocalTetMesh* find(const PieceSurface& region) const {
    auto it = meshes_.find(key(region));
    return it == meshes_.end() ? nullptr : &it->second;
  }
  void keep(const PieceSurface& region, LocalTetMesh mesh) { meshes_[key(region)] = std::move(mesh); }

 private:
  static std::pair<std::vector<Point3>, std::vector<Triangle>> key(const PieceSurface& region) {
    return {region.points, region.triangles};
  }
  std::map<std::pair<std::vector<Point3>, std::vector<Triangle>>, LocalTetMesh> meshes_;
};

// Meshes every part (those not in the cache in one batch); returns the parts that failed, with
// the failure of the first.
std::vector<std::int32_t> mesh_parts(std::vector<Part>& parts, const TetMesh& mesh, const SurfaceMesh& input,
                                     const RegionMesher& mesher, RegionCache& cache, Failure& failure) {
  std::vector<std::int32_t> scratch(mesh.points.size(), -1);
  std::vector<PieceSurface> regions(parts.size()), batch;
  std::vector<std::size_t> in_batch;
  for (std::size_t c = 0; c < parts.size(); ++c) {
    Part& part = parts[c];
    close_part(part, input, scratch);
    PieceSurface& region = regions[c];
    region.index = static_cast<int>(c);
    region.seam_region = true;
    region.triangles = part.faces;
    region.global_ids = part.ids;
    for (auto id : part.ids) region.points.push_back(mesh.points[id]);
    if (const LocalTetMesh* known = cache.find(region)) {
      part.mesh = *known;
    } else {
      batch.push_back(region);
      in_batch.push_back(c);
    }
  }
  std::vector<PieceOutcome> outcomes = batch.empty() ? std::vector<PieceOutcome>() : mesher(batch);
  std::vector<std::int32_t> failed;
  for (std::size_t i = 0; i < in_batch.size(); ++i) {
    const std::size_t c = in_batch[i];
    if (outcomes[i].failure) {
      if (failed.empty()) failure = *outcomes[i].failure;
      failed.push_back(static_cast<std::int32_t>(c));
      continue;
    }
    parts[c].mesh = std::move(outcomes[i].result.mesh);
    cache.keep(regions[c], parts[c].mesh);
  }
  std::sort(failed.begin(), failed.end());
  return failed;
}

// Adds to the region every tet sharing a vertex with a failed part.
void grow_region(const TetMesh& mesh, const std::vector<std::int32_t>& component, const std::vector<std::int32_t>& failed,
                 std::vector<char>& in_region) {
  std::vector<char> failing(failed.empty() ? 0 : static_cast<std::size_t>(failed.back()) + 1, 0);
  for (auto c : failed) failing[c] = 1;
  std::vector<char> touched(mesh.points.size(), 0);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    if (component[t] >= 0 && static_cast<std::size_t>(component[t]) < failing.size() && failing[component[t]])
      for (auto v : mesh.tets[t]) touched[v] = 1;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    if (!in_region[t])
      for (auto v : mesh.tets[t])
        if (touched[v]) in_region[t] = 1;
}

// Replaces the region's tets by the parts' new tets. Tets outside the region keep their order
// and their neighbours among themselves; faces towards the region are joined to the new tets.
void replace_region(TetMesh& mesh, const std::vector<char>& in_region, const std::vector<Part>& parts,
                    SeamStats& stats) {
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
      ++stats.tets_in;
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
    stats.tets_out += static_cast<std::int64_t>(part.mesh.tets.size());
  }
  connect_open_faces(tets, neighbours, &seam);
  mesh.tets = std::move(tets);
  mesh.neighbours = std::move(neighbours);
  mesh.piece = std::move(piece);
}

// Drops unused points (the removed vertices, and input vertices no triangle uses), keeping order.
void drop_unused_points(TetMesh& mesh, const Removed& removed, SeamStats& stats) {
  const std::vector<char> used = used_vertices(mesh.points.size(), mesh.tets);
  const std::vector<std::int32_t> new_id = compact_ids(used);
  std::vector<Point3> points;
  points.reserve(mesh.points.size());
  for (std::size_t v = 0; v < mesh.points.size(); ++v) {
    if (used[v])
      points.push_back(mesh.points[v]);
    else if (removed.is_cut_vertex(static_cast<std::int32_t>(v)))
      ++stats.cut_vertices_removed;
    else if (removed.contains(static_cast<std::int32_t>(v)))
      ++stats.cap_points_removed;
  }
  for (auto& t : mesh.tets)
    for (auto& v : t) {
      if (removed.contains(v)) throw InternalError("seam healing left a vertex it had to remove in the mesh");
      v = new_id[v];
    }
  mesh.points = std::move(points);
}

}  // namespace

SeamStats heal_seams(TetMesh& mesh, const SurfaceMesh& input, const SplitSurface& split, bool remove_cap_points,
                     const RegionMesher& mesher) {
  SeamStats stats;
  const std::int32_t first_cap = split.input_vertex_count + split.cut_vertex_count();
  const Removed removed{split.input_vertex_count, first_cap,
                        first_cap + (remove_cap_points ? static_cast<std::int32_t>(split.cap_point_plane.size()) : 0),
                        split};
  const FragmentParents parent_of = fragment_parents(split);

  // The region to re-mesh: every tet touching a removed vertex.
  std::vector<char> in_region(mesh.tets.size(), 0);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    for (auto v : mesh.tets[t])
      if (removed.contains(v)) in_region[t] = 1;

  // The region falls into connected parts (one per cut, or per group of cuts that share tets),
  // each re-meshed on its own, in parallel: smaller TetGen runs, and a failure names the cut
  // planes involved so only those need to move. A part TetGen cannot re-mesh without touching
  // its boundary (the faces of the often flat tets around it) grows by a layer of tets and is
  // tried again: the larger it is, the closer the job gets to meshing the input triangles alone.
  constexpr int kMaxGrowth = 3;
  std::vector<std::int32_t> component;
  std::vector<Part> parts;
  RegionCache cache;
  for (int growth = 0;; ++growth) {
    const std::int32_t count = label_tet_regions(
        mesh.neighbours, [&](std::size_t t) { return in_region[t] != 0; }, [](std::size_t, int) { return true; },
        component);
    parts = region_parts(mesh, in_region, component, count, removed, parent_of);
    Failure failure;
    const std::vector<std::int32_t> failed = mesh_parts(parts, mesh, input, mesher, cache, failure);
    if (failed.empty()) break;
    if (growth == kMaxGrowth) {
      const Part& part = parts[failed.front()];
      std::string planes;
      for (int p : part.planes) planes += (planes.empty() ? "" : ", ") + std::to_string(p);
      failure.message = "re-meshing the seam near cut plane(s) " + planes + ": " + failure.text();
      failure.piece = -1;
      failure.planes = part.planes;
      throw MeshingError(failure);
    }
    grow_region(mesh, component, failed, in_region);
  }
  stats.regions = static_cast<std::int64_t>(parts.size());
  replace_region(mesh, in_region, parts, stats);
  drop_unused_points(mesh, removed, stats);
  return stats;
}

}  // namespace partet
