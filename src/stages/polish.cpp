#include "stages/polish.hpp"

#include <algorithm>
#include <limits>
#include <numeric>
#include <string>
#include <unordered_map>
#include <vector>

#include "partet/errors.hpp"
#include "stages/quality.hpp"
#include "stages/tet_region.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

// The worst measures over a set of tets.
struct Worst {
  double min_dihedral_deg = 180;
  double amips = 0;
  void add(const TetShape& s) {
    min_dihedral_deg = std::min(min_dihedral_deg, s.min_dihedral_deg);
    amips = std::max(amips, s.amips);
  }
};

// A neighbourhood's tets as the polish judges them: the worst, and how many are poor.
struct Judged {
  Worst worst;
  std::int64_t poor = 0;
  void add(const TetShape& s, const PolishOptions& options) {
    worst.add(s);
    poor += s.min_dihedral_deg < options.min_dihedral_deg || s.amips > options.max_amips;
  }
  // Never worse in the worst tet (up to rounding: a tet kept as it was may be measured from
  // another corner) nor in the number of poor tets, and better in one of them: a tet TetGen must
  // keep (four input vertices, two faces on the surface) must not stop its neighbours from
  // improving.
  bool better_than(const Judged& o) const {
    constexpr double kRounding = 1e-9;
    const bool not_worse = worst.min_dihedral_deg >= o.worst.min_dihedral_deg - kRounding &&
                           worst.amips <= o.worst.amips * (1 + kRounding) && poor <= o.poor;
    const bool better = worst.min_dihedral_deg > o.worst.min_dihedral_deg + kRounding ||
                        worst.amips < o.worst.amips * (1 - kRounding) || poor < o.poor;
    return not_worse && better;
  }
};

TetShape shape_of(const TetMesh& mesh, const Tet& t) {
  return tet_shape(mesh.points[t[0]], mesh.points[t[1]], mesh.points[t[2]], mesh.points[t[3]]);
}

// Whether a tet is poor, measuring its dihedral angles only when its AMIPS energy allows one
// below the bound (1-2% of the tets of a refined mesh): a scan costs a fifth as much.
class PoorTest {
 public:
  explicit PoorTest(const PolishOptions& options)
      : options_(options), measure_above_(std::min(amips_lower_bound(options.min_dihedral_deg), options.max_amips)) {}
  bool operator()(const TetMesh& mesh, const Tet& t, Worst& worst) const {
    const Point3 &a = mesh.points[t[0]], &b = mesh.points[t[1]], &c = mesh.points[t[2]], &d = mesh.points[t[3]];
    const double amips = amips_energy(a, b, c, d);
    worst.amips = std::max(worst.amips, amips);
    if (amips <= measure_above_) return false;
    const TetShape shape = tet_shape(a, b, c, d);
    worst.min_dihedral_deg = std::min(worst.min_dihedral_deg, shape.min_dihedral_deg);
    return shape.min_dihedral_deg < options_.min_dihedral_deg || shape.amips > options_.max_amips;
  }

 private:
  PolishOptions options_;
  double measure_above_;
};

// Marks the poor tets; returns how many there are, and the mesh's worst measures in `worst`.
std::int64_t mark_poor(const TetMesh& mesh, const PoorTest& is_poor, const PolishOptions& options,
                       std::vector<char>& poor, Worst& worst) {
  poor.assign(mesh.tets.size(), 0);
  worst = Worst();
  std::int64_t count = 0;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    if (is_poor(mesh, mesh.tets[t], worst)) poor[t] = 1, ++count;
  // The smallest angle is known when it is below the bound; otherwise it is among the tets
  // whose angles were skipped.
  if (worst.min_dihedral_deg >= options.min_dihedral_deg)
    for (const Tet& t : mesh.tets) worst.add(shape_of(mesh, t));
  return count;
}

// The poor tets after replace_region: kept tets keep their flags (moved with them), the new
// ones are measured. Returns how many are poor.
std::int64_t carry_poor_flags(const TetMesh& mesh, const PoorTest& is_poor, const Replacement& where,
                              std::vector<char>& poor) {
  Worst ignored;
  for (const auto& [from, to] : where.moved) poor[to] = poor[from];
  poor.resize(mesh.tets.size());
  for (auto t : where.new_tets) poor[t] = is_poor(mesh, mesh.tets[t], ignored);
  return std::count(poor.begin(), poor.end(), 1);
}

constexpr std::size_t kNoPart = static_cast<std::size_t>(-1);

// One neighbourhood: its tets' worst measures, its boundary, and its re-meshing.
struct Neighbourhood {
  Judged before;
  std::int64_t tets = 0;
  std::vector<Triangle> faces;  // global ids, outward
  RegionMesh remeshed;
};

// Numbers the neighbourhoods by their lowest tet (as sorted ids) and puts each one's faces from
// their lowest vertex in ascending order: what TetGen is given, and so the polished mesh, then
// depends on the neighbourhoods alone, not on the order of the tets (which differs between the
// band path and the whole mesh, and will between the ranks that keep their pieces).
void put_in_canonical_order(const TetMesh& mesh, std::vector<Neighbourhood>& parts,
                            std::vector<std::int32_t>& part_of) {
  constexpr std::int32_t kMax = std::numeric_limits<std::int32_t>::max();
  std::vector<Tet> lowest(parts.size(), Tet{kMax, kMax, kMax, kMax});
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    if (part_of[t] >= 0) {
      Tet sorted = mesh.tets[t];
      std::sort(sorted.begin(), sorted.end());
      lowest[part_of[t]] = std::min(lowest[part_of[t]], sorted);
    }
  std::vector<std::int32_t> order(parts.size()), rank(parts.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::int32_t a, std::int32_t b) { return lowest[a] < lowest[b]; });
  std::vector<Neighbourhood> ordered;
  ordered.reserve(parts.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    rank[order[i]] = static_cast<std::int32_t>(i);
    ordered.push_back(std::move(parts[order[i]]));
  }
  for (auto& p : part_of)
    if (p >= 0) p = rank[p];
  for (Neighbourhood& part : ordered) sort_triangles(part.faces);
  parts = std::move(ordered);
}

// The face-connected parts of the region, each with its boundary: faces towards tets outside
// it and faces on the mesh boundary.
std::vector<Neighbourhood> neighbourhoods(const TetMesh& mesh, const std::vector<char>& in_region,
                                          const PolishOptions& options, std::vector<std::int32_t>& part_of) {
  const std::int32_t count = label_tet_regions(
      mesh.neighbours, [&](std::size_t t) { return in_region[t] != 0; }, [](std::size_t, int) { return true; },
      part_of);
  std::vector<Neighbourhood> parts(static_cast<std::size_t>(count));
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    if (part_of[t] < 0) continue;
    Neighbourhood& part = parts[part_of[t]];
    ++part.tets;
    part.before.add(shape_of(mesh, mesh.tets[t]), options);
    for (int j = 0; j < 4; ++j) {
      const auto nb = mesh.neighbours[t][j];
      if (nb < 0 || part_of[nb] != part_of[t]) part.faces.push_back(outward_face(mesh.tets[t], j));
    }
  }
  put_in_canonical_order(mesh, parts, part_of);
  return parts;
}

// The shape of a tet of a re-meshed batch (local ids: surface points, then Steiner points).
TetShape shape_in(const RegionMesh& batch, const TetMesh& mesh, const Tet& t) {
  const auto surface = static_cast<std::int32_t>(batch.ids.size());
  auto point = [&](std::int32_t v) -> const Point3& {
    return v < surface ? mesh.points[batch.ids[v]] : batch.mesh.steiner_points[v - surface];
  };
  return tet_shape(point(t[0]), point(t[1]), point(t[2]), point(t[3]));
}

// Neighbourhoods are meshed in batches, one TetGen run per batch with one shell per
// neighbourhood: a run's fixed cost (a process forked from a large one, a message) is ten times
// what meshing one neighbourhood costs. Batches close at this many triangles, so that several
// spread over the ranks when there is much to re-mesh. Made in neighbourhood order, so they do
// not depend on the number of ranks.
constexpr std::size_t kBatchTriangles = 4000;

// The neighbourhoods worth re-meshing (see PolishOptions::largest_neighbourhood), in batches.
std::vector<std::vector<std::size_t>> batches_of(const std::vector<Neighbourhood>& parts,
                                                 const PolishOptions& options) {
  std::vector<std::vector<std::size_t>> batches;
  std::size_t triangles = kBatchTriangles;
  for (std::size_t c = 0; c < parts.size(); ++c) {
    if (parts[c].tets > options.largest_neighbourhood || parts[c].before.poor > options.most_poor_tets) continue;
    if (triangles >= kBatchTriangles) batches.emplace_back(), triangles = 0;
    batches.back().push_back(c);
    triangles += parts[c].faces.size();
  }
  return batches;
}

// A batch fails as a whole when one of its neighbourhoods does: its halves are tried next, so
// the one that fails is found in a few rounds rather than one run per neighbourhood.
void split_in_halves(const std::vector<std::size_t>& batch, std::vector<std::vector<std::size_t>>& next) {
  if (batch.size() < 2) return;
  const auto middle = batch.begin() + static_cast<std::ptrdiff_t>(batch.size() / 2);
  next.emplace_back(batch.begin(), middle);
  next.emplace_back(middle, batch.end());
}

// A batch's surface: the boundaries of its neighbourhoods, numbered together. `face_part` gets
// the neighbourhood of each of its triangles.
PieceSurface batch_surface(const std::vector<std::size_t>& batch, const std::vector<Neighbourhood>& parts,
                           const TetMesh& mesh, int index, std::vector<std::int32_t>& ids,
                           std::vector<std::size_t>& face_part) {
  std::vector<Triangle> faces;
  face_part.clear();
  for (auto c : batch) {
    faces.insert(faces.end(), parts[c].faces.begin(), parts[c].faces.end());
    face_part.resize(faces.size(), c);
  }
  return region_surface(std::move(faces), mesh, index, ids);
}

// Splits a batch's tets by neighbourhood: tets are connected across their faces inside one
// neighbourhood only, and each connected set has a face on the surface, which names it.
std::vector<std::size_t> neighbourhood_of_tets(const LocalTetMesh& result, const PieceSurface& surface,
                                               const std::vector<std::size_t>& face_part) {
  std::unordered_map<FaceKey, std::size_t, FaceKeyHash> part_of_face;
  for (std::size_t f = 0; f < surface.triangles.size(); ++f)
    part_of_face.emplace(FaceKey(surface.triangles[f]), face_part[f]);
  std::vector<std::int32_t> component;
  const std::int32_t count = label_tet_regions(
      result.neighbours, [](std::size_t) { return true; }, [](std::size_t, int) { return true; }, component);
  std::vector<std::size_t> part_of_component(static_cast<std::size_t>(count), kNoPart);
  for (std::size_t t = 0; t < result.tets.size(); ++t)
    for (int j = 0; j < 4; ++j)
      if (result.neighbours[t][j] < 0)
        part_of_component[component[t]] = part_of_face.at(FaceKey(outward_face(result.tets[t], j)));
  std::vector<std::size_t> part(result.tets.size());
  for (std::size_t t = 0; t < result.tets.size(); ++t) {
    part[t] = part_of_component[component[t]];
    if (part[t] == kNoPart) throw InternalError("polish: re-meshed tets reach no neighbourhood's boundary");
  }
  return part;
}

// The tets of a batch's result that belong to the kept neighbourhoods, with their neighbours
// renumbered (a neighbourhood's tets only neighbour each other).
LocalTetMesh kept_tets(LocalTetMesh&& result, const std::vector<std::size_t>& part, const std::vector<char>& kept) {
  std::vector<std::int32_t> new_index(result.tets.size(), -1);
  LocalTetMesh out;
  out.steiner_points = std::move(result.steiner_points);
  for (std::size_t t = 0; t < result.tets.size(); ++t)
    if (kept[part[t]]) new_index[t] = static_cast<std::int32_t>(out.tets.size()), out.tets.push_back(result.tets[t]);
  for (std::size_t t = 0; t < result.tets.size(); ++t) {
    if (!kept[part[t]]) continue;
    Tet nb = result.neighbours[t];
    for (auto& n : nb) n = n >= 0 ? new_index[n] : -1;
    out.neighbours.push_back(nb);
  }
  return out;
}

// Judges a batch's re-meshed neighbourhoods against their old tets: marks the better ones kept,
// and leaves in `batch_mesh` only their tets. Returns whether any is kept.
bool keep_better(const std::vector<std::size_t>& batch, const std::vector<Neighbourhood>& parts,
                 const PieceSurface& surface, const std::vector<std::size_t>& face_part, const TetMesh& mesh,
                 const PolishOptions& options, RegionMesh& batch_mesh, std::vector<char>& kept) {
  const std::vector<std::size_t> part = neighbourhood_of_tets(batch_mesh.mesh, surface, face_part);
  std::unordered_map<std::size_t, Judged> after;
  for (std::size_t t = 0; t < part.size(); ++t)
    after[part[t]].add(shape_in(batch_mesh, mesh, batch_mesh.mesh.tets[t]), options);
  bool any = false;
  for (auto c : batch)
    if (after[c].better_than(parts[c].before)) kept[c] = 1, any = true;
  if (any) batch_mesh.mesh = kept_tets(std::move(batch_mesh.mesh), part, kept);
  return any;
}

// Re-meshes every neighbourhood (in batches; a batch that fails, in halves) and keeps
// those that got better. Returns their new tets; in_region is cleared where a neighbourhood is
// not kept.
std::vector<RegionMesh> remesh_and_keep_better(const std::vector<Neighbourhood>& parts,
                                               const std::vector<std::int32_t>& part_of, const TetMesh& mesh,
                                               const PolishOptions& options, const std::string& optimization,
                                               const PolishMesher& mesher, std::vector<char>& in_region,
                                               PolishStats& stats) {
  std::vector<char> kept(parts.size(), 0);
  std::vector<RegionMesh> better;
  std::vector<std::vector<std::size_t>> batches = batches_of(parts, options);
  std::int64_t remeshed = 0;
  for (const auto& batch : batches) remeshed += static_cast<std::int64_t>(batch.size());
  while (!batches.empty()) {
    std::vector<PieceSurface> surfaces(batches.size());
    std::vector<RegionMesh> results(batches.size());
    std::vector<std::vector<std::size_t>> face_part(batches.size());
    for (std::size_t b = 0; b < batches.size(); ++b)
      surfaces[b] = batch_surface(batches[b], parts, mesh, static_cast<int>(b), results[b].ids, face_part[b]);
    std::vector<PieceOutcome> outcomes = mesher(surfaces, optimization);
    std::vector<std::vector<std::size_t>> failed;
    for (std::size_t b = 0; b < batches.size(); ++b) {
      if (outcomes[b].failure) {
        if (outcomes[b].failure->kind == FailureKind::runaway) stats.ran_away = true;
        else split_in_halves(batches[b], failed);
        continue;
      }
      results[b].mesh = std::move(outcomes[b].result.mesh);
      if (!keep_better(batches[b], parts, surfaces[b], face_part[b], mesh, options, results[b], kept)) continue;
      stats.tets_out += static_cast<std::int64_t>(results[b].mesh.tets.size());
      better.push_back(std::move(results[b]));
    }
    batches = stats.ran_away ? decltype(failed)() : std::move(failed);
  }
  for (std::size_t t = 0; t < in_region.size(); ++t) {
    if (in_region[t] && !kept[part_of[t]]) in_region[t] = 0;
    stats.tets_in += in_region[t];
  }
  stats.regions += remeshed;
  stats.left += static_cast<std::int64_t>(parts.size()) - remeshed;
  stats.improved += std::count(kept.begin(), kept.end(), 1);
  return better;
}

// The TetGen optimization an attempt asks for: the first re-meshes with the switches of the
// pieces, later ones with TetGen's most thorough optimization (level 9, every scheme).
std::string optimization_of(int attempt) { return attempt == 0 ? "" : "9/7"; }

// Attempt a: the poor tets grown by a + 1 layers of tets sharing a vertex, re-meshed.
void polish_attempt(TetMesh& mesh, const PolishOptions& options, const PoorTest& is_poor, int attempt,
                    const PolishMesher& mesher, std::vector<char>& poor, PolishStats& stats) {
  std::vector<char> in_region = poor;
  for (int layer = 0; layer <= attempt; ++layer)
    add_layer(
        mesh, [&](std::size_t t) { return in_region[t] != 0; }, in_region);
  std::vector<std::int32_t> part_of;
  const std::vector<Neighbourhood> parts = neighbourhoods(mesh, in_region, options, part_of);
  std::vector<RegionMesh> better =
      remesh_and_keep_better(parts, part_of, mesh, options, optimization_of(attempt), mesher, in_region, stats);
  if (better.empty()) return;
  const Replacement where = replace_region(mesh, in_region, std::move(better));
  stats.poor_after = carry_poor_flags(mesh, is_poor, where, poor);
}

}  // namespace

PolishStats polish_poor_tets(TetMesh& mesh, const PolishOptions& options, const PolishMesher& mesher) {
  PolishStats stats;
  const PoorTest is_poor(options);
  std::vector<char> poor;
  Worst worst;
  stats.poor_before = stats.poor_after = mark_poor(mesh, is_poor, options, poor, worst);
  stats.min_dihedral_before = stats.min_dihedral_after = worst.min_dihedral_deg;
  stats.amips_max_before = stats.amips_max_after = worst.amips;
  if (stats.poor_before == 0) return stats;
  for (int attempt = 0; attempt < options.attempts && stats.poor_after > 0 && !stats.ran_away; ++attempt)
    polish_attempt(mesh, options, is_poor, attempt, mesher, poor, stats);
  drop_unused_points(mesh);
  mark_poor(mesh, is_poor, options, poor, worst);
  stats.min_dihedral_after = worst.min_dihedral_deg;
  stats.amips_max_after = worst.amips;
  return stats;
}

}  // namespace partet
