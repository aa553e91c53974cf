#include "stages/seam_healing.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <string>
#include <unordered_map>

#include "partet/errors.hpp"
#include "common/log.hpp"
#include "common/stage_timer.hpp"
#include "stages/seam_chains.hpp"
#include "stages/seam_rounds.hpp"
#include "stages/tet_region.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

// The vertices seam healing removes, ids [first, end) of the merged mesh: the cut vertices
// [first, first_cap), then (when healing) the caps' interior points. A round takes those
// selected for it.
struct Removed {
  std::int32_t first, first_cap, end;
  const SplitSurface& split;
  const std::vector<char>* selected = nullptr;  // by v - first; all when null
  const std::vector<int>* chain_of_plane = nullptr;
  bool in_round(std::int32_t v) const { return !selected || (*selected)[v - first]; }
  bool contains(std::int32_t v) const { return v >= first && v < end && in_round(v); }
  bool is_cut_vertex(std::int32_t v) const { return v >= first && v < first_cap && in_round(v); }
  bool touches(const Triangle& f) const { return is_cut_vertex(f[0]) || is_cut_vertex(f[1]) || is_cut_vertex(f[2]); }
  int plane_of(std::int32_t v) const {
    return v < first_cap ? split.cut_vertex_plane[v - first] : split.cap_point_plane[v - first_cap];
  }
  std::size_t size() const { return static_cast<std::size_t>(end - first); }
  int chain_of(std::int32_t v) const { return (*chain_of_plane)[plane_of(v)]; }
  std::int32_t id(std::size_t i) const { return first + static_cast<std::int32_t>(i); }
};

// The Steiner points a round's parts added, in the order they were appended: how many, of which chain.
struct NewPoints {
  int chain;
  std::size_t count;
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
  std::vector<Triangle> faces;        // its boundary, global ids
  std::vector<std::int32_t> parents;  // input triangles replacing its boundary fragments
  std::vector<int> planes;            // cut planes of its cut vertices
  int chain = -1;                     // its chain (all its removed vertices are of one)
  RegionMesh remeshed;
};

// Where region tet t is in the region (ascending). Per-tet data of a region is stored by this
// position, not per mesh tet: at 33M tets (22M input faces) a label per mesh tet cost rank 0
// 130 MB.
std::size_t position_in(const std::vector<std::int32_t>& region, std::int32_t t) {
  return static_cast<std::size_t>(std::lower_bound(region.begin(), region.end(), t) - region.begin());
}

// Splits the region into parts; part_of gets each region tet's part, by its position in the
// region. Removed vertices that share a tet are in one part (a vertex's whole star must be
// re-meshed at once); tets without a removed vertex join the part of a neighbour. Tets of
// different cuts that merely touch stay in different parts (with the faces between them fixed),
// so a solid whose interior tets span two cuts still heals as several regions, on several ranks.
// Nothing here depends on the order of the tets (the band path and the whole mesh order them
// differently, and the parts' order numbers healing's new points): parts are numbered by their
// lowest removed vertex, and a tet reached from two parts at once joins the lower. Returns the
// number of parts.
std::int32_t label_parts(const TetMesh& mesh, const std::vector<std::int32_t>& region,
                         const std::vector<char>& in_region, const Removed& removed,
                         std::vector<std::int32_t>& part_of) {
  DisjointSets sets(removed.first, removed.size());
  std::vector<char> present(removed.size(), 0);
  for (auto t : region) {
    std::int32_t first = -1;
    for (auto v : mesh.tets[t])
      if (removed.contains(v)) {
        present[v - removed.first] = 1;
        if (first < 0)
          first = v;
        else
          sets.join(v, first);
      }
  }
  std::vector<std::int32_t> number(sets.size(), -1);
  std::int32_t count = 0;
  for (std::size_t i = 0; i < present.size(); ++i)
    if (present[i]) {
      std::int32_t& n = number[sets.find(removed.first + static_cast<std::int32_t>(i))];
      if (n < 0) n = count++;
    }
  // The tets with removed vertices, then the others layer by layer (positions in the region).
  part_of.assign(region.size(), -1);
  std::vector<std::size_t> layer;
  for (std::size_t i = 0; i < region.size(); ++i)
    for (auto v : mesh.tets[region[i]])
      if (removed.contains(v)) {
        part_of[i] = number[sets.find(v)];
        layer.push_back(i);
        break;
      }
  std::size_t labelled = layer.size();
  std::vector<std::int32_t> claim(region.size(), -1);  // the lowest part reaching a tet in this layer
  while (!layer.empty()) {
    std::vector<std::size_t> next;
    for (std::size_t i : layer)
      for (auto nb : mesh.neighbours[region[i]]) {
        if (nb < 0 || !in_region[nb]) continue;
        const std::size_t at = position_in(region, nb);
        if (part_of[at] >= 0) continue;
        if (claim[at] < 0) next.push_back(at);
        if (claim[at] < 0 || part_of[i] < claim[at]) claim[at] = part_of[i];
      }
    for (std::size_t at : next) part_of[at] = claim[at];
    labelled += next.size();
    layer = std::move(next);
  }
  if (labelled != region.size()) throw InternalError("seam healing: a region tet reaches no removed vertex");
  return count;
}

// Collects each part's boundary (`part_of` as label_parts gives it): faces towards tets outside
// the part, and mesh-boundary faces without a cut vertex. Mesh-boundary faces with a
// cut vertex are fragments of split input triangles, recorded by their input triangle (all
// fragments of a triangle share cut vertices, so they lie in one part).
std::vector<Part> region_parts(const TetMesh& mesh, const std::vector<std::int32_t>& region,
                               const std::vector<char>& in_region, const std::vector<std::int32_t>& part_of,
                               std::int32_t part_count, const Removed& removed, const FragmentParents& parent_of) {
  std::vector<Part> parts(part_count);
  for (std::size_t i = 0; i < region.size(); ++i) {
    const std::int32_t t = region[i];
    Part& part = parts[part_of[i]];
    for (auto v : mesh.tets[t])
      if (removed.contains(v)) {
        part.planes.push_back(removed.plane_of(v));
        part.chain = removed.chain_of(v);
      }
    for (int j = 0; j < 4; ++j) {
      const auto nb = mesh.neighbours[t][j];
      if (nb >= 0 && in_region[nb] && part_of[position_in(region, nb)] == part_of[i]) continue;
      const Triangle face = outward_face(mesh.tets[t], j);
      if (nb < 0 && removed.touches(face)) {
        auto it = parent_of.find(FaceKey(face));
        if (it == parent_of.end())
          throw InternalError("seam healing: a boundary face with a cut vertex is no fragment of an input triangle");
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

// Closes a part's boundary with its input triangles; its surface for TetGen. TetGen fills a
// region differently when its faces come in another order, so they go each from its lowest
// vertex, in ascending order: the result depends on the part alone, not on the order of the tets
// it was cut from.
PieceSurface close_part(Part& part, const TetMesh& mesh, const SurfaceMesh& input, int index) {
  sort_unique(part.parents);
  for (auto f : part.parents) part.faces.push_back(input.triangles[f]);
  sort_triangles(part.faces);
  sort_unique(part.planes);
  return region_surface(part.faces, mesh, index, part.remeshed.ids);
}

// Re-meshed regions by content: after a region grows, the regions it did not touch come back
// unchanged and need no new TetGen run.
class RegionCache {
 public:
  const LocalTetMesh* find(const PieceSurface& region) const {
    auto it = meshes_.find(key(region));
    return it == meshes_.end() ? nullptr : &it->second;
  }
  void keep(PieceSurface&& region, LocalTetMesh mesh) {
    meshes_[{std::move(region.points), std::move(region.triangles)}] = std::move(mesh);
  }

 private:
  static std::pair<std::vector<Point3>, std::vector<Triangle>> key(const PieceSurface& region) {
    return {region.points, region.triangles};
  }
  std::map<std::pair<std::vector<Point3>, std::vector<Triangle>>, LocalTetMesh> meshes_;
};

// Meshes every part (those not in the cache in one batch); returns the parts that failed, with
// the failure of the first. The cache keeps the others' meshes only when some part failed (the
// region then grows and is meshed again); otherwise it would copy every new tet.
std::vector<std::int32_t> mesh_parts(std::vector<Part>& parts, const TetMesh& mesh, const SurfaceMesh& input,
                                     const RegionMesher& mesher, RegionCache& cache, Failure& failure) {
  std::vector<PieceSurface> batch;
  std::vector<std::size_t> in_batch;
  for (std::size_t c = 0; c < parts.size(); ++c) {
    Part& part = parts[c];
    PieceSurface region = close_part(part, mesh, input, static_cast<int>(c));
    if (const LocalTetMesh* known = cache.find(region)) {
      part.remeshed.mesh = *known;
    } else {
      batch.push_back(std::move(region));
      in_batch.push_back(c);
    }
  }
  std::vector<PieceOutcome> outcomes = batch.empty() ? std::vector<PieceOutcome>() : mesher(batch);
  const bool regions_grow =
      std::any_of(outcomes.begin(), outcomes.end(), [](const PieceOutcome& o) { return o.failure.has_value(); });
  std::vector<std::int32_t> failed;
  for (std::size_t i = 0; i < in_batch.size(); ++i) {
    const std::size_t c = in_batch[i];
    if (outcomes[i].failure) {
      if (failed.empty()) failure = *outcomes[i].failure;
      failed.push_back(static_cast<std::int32_t>(c));
      continue;
    }
    std::string planes;
    for (int p : parts[c].planes) planes += (planes.empty() ? "" : ",") + std::to_string(p);
    log::debug("seam region " + std::to_string(c) + ": " + std::to_string(batch[i].triangles.size()) +
               " triangles, cut(s) " + planes + " -> " + std::to_string(outcomes[i].result.mesh.tets.size()) +
               " tets in " + std::to_string(outcomes[i].seconds) + " s");
    parts[c].remeshed.mesh = std::move(outcomes[i].result.mesh);
    if (regions_grow) cache.keep(std::move(batch[i]), parts[c].remeshed.mesh);
  }
  std::sort(failed.begin(), failed.end());
  return failed;
}

// Adds to the region every tet sharing a vertex with a failed part (`failed` ascending;
// `part_of` as label_parts gives it).
void grow_region(const TetMesh& mesh, const std::vector<std::int32_t>& region, const std::vector<std::int32_t>& part_of,
                 const std::vector<std::int32_t>& failed, std::vector<char>& in_region) {
  std::vector<char> failing(failed.empty() ? 0 : static_cast<std::size_t>(failed.back()) + 1, 0);
  for (auto c : failed) failing[c] = 1;
  add_layer(
      mesh,
      [&](std::size_t t) {
        if (!in_region[t]) return false;
        const std::int32_t part = part_of[position_in(region, static_cast<std::int32_t>(t))];
        return static_cast<std::size_t>(part) < failing.size() && failing[part];
      },
      in_region);
}

// Counts the removed vertices gone from the mesh and, with `drop`, drops them (and input vertices
// no triangle uses), keeping order.
void drop_removed_points(TetMesh& mesh, const Removed& removed, bool drop, SeamStats& stats) {
  const std::vector<char> used = drop ? drop_unused_points(mesh) : used_vertices(mesh.points.size(), mesh.tets);
  for (std::size_t v = 0; v < used.size(); ++v) {
    const auto id = static_cast<std::int32_t>(v);
    if (used[v] && removed.contains(id)) throw InternalError("seam healing left a vertex it had to remove in the mesh");
    if (used[v]) continue;
    if (removed.is_cut_vertex(id))
      ++stats.cut_vertices_removed;
    else if (removed.contains(id))
      ++stats.cap_points_removed;
  }
}

// Groups of cuts that must heal together: cuts that split one input triangle between them (the
// triangle returns whole).
std::vector<int> groups_of_planes(const SplitSurface& split) {
  const int planes = split.plane_count();
  std::vector<char> joined_to_previous(static_cast<std::size_t>(planes), 0);
  std::unordered_map<std::int32_t, int> lowest_plane;  // input triangle -> lowest plane cutting it
  for (std::size_t t = 0; t < split.triangles.size(); ++t)
    for (auto v : split.triangles[t])
      if (split.is_cut_vertex(v)) {
        const int plane = split.cut_vertex_plane[v - split.input_vertex_count];
        auto [it, fresh] = lowest_plane.emplace(split.parent[t], plane);
        for (int j = std::min(it->second, plane) + 1; j <= std::max(it->second, plane); ++j) joined_to_previous[j] = 1;
        it->second = std::min(it->second, plane);
      }
  std::vector<int> group(static_cast<std::size_t>(planes), 0);
  for (int j = 1; j < planes; ++j) group[j] = group[j - 1] + (joined_to_previous[j] ? 0 : 1);
  return group;
}

// The round's region: the stars of its removed vertices (among `candidates`, ascending) grown by
// `layers` layers of tets across their faces. Marks it in `in_region`; returns it ascending.
std::vector<std::int32_t> round_region(const TetMesh& mesh, const Removed& removed,
                                       const std::vector<std::int32_t>& candidates, int layers,
                                       std::vector<char>& in_region) {
  in_region.assign(mesh.tets.size(), 0);
  std::vector<std::int32_t> region;
  for (auto t : candidates)
    for (auto v : mesh.tets[t])
      if (removed.contains(v)) {
        in_region[t] = 1;
        region.push_back(t);
        break;
      }
  for (std::size_t layer = 0, begin = 0; layer < static_cast<std::size_t>(layers); ++layer) {
    const std::size_t end = region.size();
    for (std::size_t i = begin; i < end; ++i)
      for (auto nb : mesh.neighbours[region[i]])
        if (nb >= 0 && !in_region[nb]) in_region[nb] = 1, region.push_back(nb);
    begin = end;
  }
  std::sort(region.begin(), region.end());
  return region;
}

// After a round, the only tets that can hold a vertex still to remove: the round's star tets
// outside its region (at their slots after the splice) and the new tets (their boundary
// vertices include any vertex left on the region's boundary). Ascending.
std::vector<std::int32_t> surviving_stars(const std::vector<std::int32_t>& star_tets,
                                          const std::vector<char>& in_region, const Replacement& where) {
  const std::unordered_map<std::int32_t, std::int32_t> moved_to(where.moved.begin(), where.moved.end());
  std::vector<std::int32_t> survivors = where.new_tets;
  for (auto t : star_tets) {
    if (in_region[t]) continue;
    const auto it = moved_to.find(t);
    survivors.push_back(it == moved_to.end() ? t : it->second);
  }
  std::sort(survivors.begin(), survivors.end());
  return survivors;
}

// Re-meshes the stars of the round's removed vertices (grown by options.layers). The region
// falls into parts, each re-meshed on its own, in parallel: smaller TetGen runs, and a failure
// names the cut planes involved so only those need to move. A part TetGen cannot re-mesh without
// touching its boundary (the faces of the often flat tets around it) grows by a layer of tets
// and is tried again: the larger it is, the closer the job gets to meshing the input triangles
// alone.
// Returns the tets that may hold a vertex left for later rounds (see surviving_stars).
std::vector<std::int32_t> heal_round(TetMesh& mesh, const SurfaceMesh& input, const Removed& removed,
                                     const FragmentParents& parent_of, const std::vector<std::int32_t>& star_tets,
                                     const HealOptions& options, const RegionMesher& mesher, SeamStats& stats,
                                     std::vector<NewPoints>& new_points, StepClock& clock) {
  std::vector<char> in_region;
  std::vector<std::int32_t> region = round_region(mesh, removed, star_tets, options.layers, in_region);
  if (region.empty()) return star_tets;
  clock.lap("region");

  constexpr int kMaxGrowth = 3;
  std::vector<std::int32_t> part_of;  // by position in the region
  std::vector<Part> parts;
  RegionCache cache;
  for (int growth = 0;; ++growth) {
    const std::int32_t count = label_parts(mesh, region, in_region, removed, part_of);
    parts = region_parts(mesh, region, in_region, part_of, count, removed, parent_of);
    clock.lap("parts");
    Failure failure;
    const std::vector<std::int32_t> failed = mesh_parts(parts, mesh, input, mesher, cache, failure);
    clock.lap("meshing");
    if (failed.empty()) break;
    // A larger region helps TetGen keep its boundary, not meet a quality bound it cannot meet.
    if (growth == kMaxGrowth || failure.kind == FailureKind::runaway) {
      const Part& part = parts[failed.front()];
      std::string planes;
      for (int p : part.planes) planes += (planes.empty() ? "" : ", ") + std::to_string(p);
      failure.message = "re-meshing the seam near cut plane(s) " + planes + ": " + failure.text();
      failure.piece = -1;
      failure.planes = part.planes;
      throw MeshingError(failure);
    }
    grow_region(mesh, region, part_of, failed, in_region);
    region = marked_tets(in_region);
  }
  cache = RegionCache();  // its copies are not needed any more
  const std::size_t part_count = parts.size();
  stats.regions += static_cast<std::int64_t>(part_count);
  std::vector<RegionMesh> remeshed;
  remeshed.reserve(parts.size());
  for (Part& part : parts) {
    new_points.push_back({part.chain, part.remeshed.mesh.steiner_points.size()});
    remeshed.push_back(std::move(part.remeshed));
  }
  std::vector<Part>().swap(parts);
  const Replacement where = replace_region(mesh, in_region, std::move(remeshed));
  clock.lap("splice");
  log::debug("seam healing round: " + std::to_string(part_count) + " regions of " + std::to_string(region.size()) +
             " tets; " + clock.steps);
  return surviving_stars(star_tets, in_region, where);
}

// The vertices healing removes, grouped (cuts splitting one input triangle heal together) and
// chained (seam_chains.hpp) on the mesh as it is.
struct RemovedGroups {
  std::vector<int> group_left;  // by v - first: the group of cuts of each vertex still to remove, or -1
  SeamChains chains;
  std::vector<int> chain_of_plane;  // -1: no vertex of its chain is left
};

// find_chains(group_left, groups): the chains, on the mesh or on the band parts' links.
template <class FindChains>
RemovedGroups removed_groups(const Removed& all, const FindChains& find_chains) {
  const std::vector<int> group_of_plane = groups_of_planes(all.split);
  RemovedGroups r;
  r.group_left.resize(all.size());
  for (std::size_t v = 0; v < r.group_left.size(); ++v) r.group_left[v] = group_of_plane[all.plane_of(all.id(v))];
  const int groups = group_of_plane.empty() ? 0 : group_of_plane.back() + 1;
  r.chains = find_chains(r.group_left, groups);
  r.chain_of_plane.resize(group_of_plane.size());
  for (std::size_t p = 0; p < group_of_plane.size(); ++p) r.chain_of_plane[p] = r.chains.of_group[group_of_plane[p]];
  return r;
}

// The vertices healing removes, with these options.
Removed removed_vertices(const SplitSurface& split, const HealOptions& options) {
  const std::int32_t first_cap = split.input_vertex_count + split.cut_vertex_count();
  return Removed{
      split.input_vertex_count, first_cap,
      first_cap + (options.remove_cap_points ? static_cast<std::int32_t>(split.cap_point_plane.size()) : 0), split};
}

// Healing's new points, appended from `first_new` on as the rounds' parts made them, renumbered
// chain by chain (stably): a chain's points then come in the order its own rounds made them,
// whichever chains healed beside it, so that chains healed apart give the same numbering.
void order_new_points_by_chain(TetMesh& mesh, std::size_t first_new, const std::vector<NewPoints>& runs) {
  const auto by_chain = [&](std::size_t a, std::size_t b) { return runs[a].chain < runs[b].chain; };
  std::vector<std::size_t> order(runs.size()), from(runs.size());
  for (std::size_t r = 0, at = 0; r < runs.size(); at += runs[r].count, ++r) order[r] = r, from[r] = at;
  if (std::is_sorted(order.begin(), order.end(), by_chain)) return;
  std::stable_sort(order.begin(), order.end(), by_chain);
  std::vector<std::int32_t> new_id(mesh.points.size() - first_new);
  std::vector<Point3> points;
  points.reserve(new_id.size());
  for (std::size_t r : order)
    for (std::size_t i = 0; i < runs[r].count; ++i) {
      new_id[from[r] + i] = static_cast<std::int32_t>(first_new + points.size());
      points.push_back(mesh.points[first_new + from[r] + i]);
    }
  std::copy(points.begin(), points.end(), mesh.points.begin() + static_cast<std::ptrdiff_t>(first_new));
  const auto first = static_cast<std::int32_t>(first_new);
  for (auto& t : mesh.tets)
    for (auto& v : t)
      if (v >= first) v = new_id[v - first];
}

}  // namespace

SeamStats heal_seams(TetMesh& mesh, const SurfaceMesh& input, const SplitSurface& split, const HealOptions& options,
                     const RegionMesher& mesher) {
  SeamStats stats;
  Removed all = removed_vertices(split, options);
  const FragmentParents parent_of = fragment_parents(split);
  RemovedGroups groups = removed_groups(all, [&](const std::vector<int>& group, int count) {
    return seam_chains(mesh, all.first, group, count, options.layers + 1);
  });
  all.chain_of_plane = &groups.chain_of_plane;
  std::vector<int>& group_left = groups.group_left;
  // The piece array marks re-meshed tets (-1), so the figures count each tet once even when a
  // later round re-meshes tets of an earlier one.
  const bool had_pieces = mesh.piece.size() == mesh.tets.size();
  if (!had_pieces) mesh.piece.assign(mesh.tets.size(), 0);
  const std::int64_t tets_before = static_cast<std::int64_t>(mesh.tets.size());
  const std::size_t first_new_point = mesh.points.size();
  std::vector<NewPoints> new_points;
  Removed healing = all;
  // The first round looks at every tet; later ones only at the tets the previous one left.
  std::vector<std::int32_t> candidates;
  for (bool first_round = true;; first_round = false) {
    StepClock clock;
    const SeamRound round =
        plan_seam_round(mesh, all.first, group_left, first_round ? nullptr : &candidates, &groups.chains.of_group);
    clock.lap("plan");
    if (std::find(round.heals.begin(), round.heals.end(), 1) == round.heals.end()) break;
    healing.selected = &round.heals;
    candidates =
        heal_round(mesh, input, healing, parent_of, round.star_tets, options, mesher, stats, new_points, clock);
    for (std::size_t v = 0; v < round.heals.size(); ++v)
      if (round.heals[v]) group_left[v] = -1;
  }
  stats.chains = groups.chains.count;
  order_new_points_by_chain(mesh, first_new_point, new_points);
  stats.tets_out = std::count(mesh.piece.begin(), mesh.piece.end(), -1);
  stats.tets_in = tets_before - (static_cast<std::int64_t>(mesh.tets.size()) - stats.tets_out);
  if (!had_pieces) std::vector<std::int32_t>().swap(mesh.piece);
  drop_removed_points(mesh, all, options.drop_points, stats);
  return stats;
}

namespace {

std::vector<std::vector<int>> planes_of_chains(const RemovedGroups& groups) {
  std::vector<std::vector<int>> planes(static_cast<std::size_t>(groups.chains.count));
  for (std::size_t p = 0; p < groups.chain_of_plane.size(); ++p)
    if (groups.chain_of_plane[p] >= 0) planes[groups.chain_of_plane[p]].push_back(static_cast<int>(p));
  return planes;
}

}  // namespace

std::vector<std::vector<int>> seam_chain_planes(const TetMesh& mesh, const SplitSurface& split,
                                               const HealOptions& options) {
  const Removed all = removed_vertices(split, options);
  return planes_of_chains(removed_groups(all, [&](const std::vector<int>& group, int count) {
    return seam_chains(mesh, all.first, group, count, options.layers + 1);
  }));
}

std::vector<std::size_t> SeamChainPlan::pieces_in(int c) const {
  std::vector<std::size_t> pieces;
  for (std::size_t p = 0; p < chain_of_part.size(); ++p)
    if (std::find(chain_of_part[p].begin(), chain_of_part[p].end(), c) != chain_of_part[p].end()) pieces.push_back(p);
  return pieces;
}

SeamChainPlan seam_chain_plan(const std::vector<BandPartLinks>& band_parts, const SplitSurface& split,
                              const HealOptions& options) {
  const Removed all = removed_vertices(split, options);
  RemovedGroups groups = removed_groups(
      all, [&](const std::vector<int>& group, int count) { return seam_chains(band_parts, all.first, group, count); });
  SeamChainPlan plan;
  plan.planes = planes_of_chains(groups);
  plan.chain_of_part = std::move(groups.chains.of_part);
  return plan;
}

BandSpec seam_band_spec(const SplitSurface& split, const HealOptions& options) {
  BandSpec spec;
  spec.input_vertex_count = split.input_vertex_count;
  // split_point_count: the welder's (the split's points may have moved into a mesh by now)
  spec.first_removed = split.input_vertex_count;
  spec.end_removed = split.input_vertex_count + split.cut_vertex_count() +
                     (options.remove_cap_points ? static_cast<std::int32_t>(split.cap_point_plane.size()) : 0);
  spec.layers = options.layers + 1;
  return spec;
}

}  // namespace partet
