#include "job/pipeline.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <exception>
#include <memory>
#include <numeric>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include "common/fnv1a.hpp"
#include "common/log.hpp"
#include "common/memory.hpp"
#include "common/test_hooks.hpp"
#include "io/scratch_bulks.hpp"
#include "job/retry_plan.hpp"
#include "partet/errors.hpp"
#include "stages/kept_band_parts.hpp"
#include "stages/merge.hpp"
#include "stages/piece_cost.hpp"
#include "stages/topology.hpp"
#include "stages/validate.hpp"

namespace partet {
namespace {

// Results of pieces meshed in earlier attempts, by content: a piece identical to one already
// meshed (same points and triangles in the same local order) reuses that result, so a retry
// re-meshes only the pieces its moved planes changed. TetGen is deterministic, so the output
// is the same either way.
class ResultCache {
 public:
  std::optional<PieceTetMesh> find(const PieceSurface& piece) const {
    if (entries_.empty()) return std::nullopt;  // the first attempt: no need to hash the piece
    auto hit = entries_.find(fingerprint(piece));
    if (hit == entries_.end() || hit->second.points != piece.points || hit->second.triangles != piece.triangles)
      return std::nullopt;
    PieceTetMesh result = hit->second.result;
    result.index = piece.index;
    return result;
  }
  void keep(const PieceSurface& piece, PieceTetMesh&& result) {
    entries_[fingerprint(piece)] = Entry{piece.points, piece.triangles, std::move(result)};
  }
  void clear() { decltype(entries_)().swap(entries_); }

 private:
  struct Entry {
    std::vector<Point3> points;
    std::vector<Triangle> triangles;
    PieceTetMesh result;
  };
  // FNV-1a over the coordinates and triangles: a quick key (hits are confirmed by comparing).
  static std::uint64_t fingerprint(const PieceSurface& piece) {
    return fnv1a(piece.triangles.data(), piece.triangles.size() * sizeof(Triangle),
                 fnv1a(piece.points.data(), piece.points.size() * sizeof(Point3)));
  }
  std::unordered_map<std::uint64_t, Entry> entries_;
};

HealOptions heal_options(const MeshOptions& options) {
  HealOptions heal{heals(options), heals(options) && !options.tetgen.quality.empty() ? 2 : 0};
  heal.keep_healed = options.spread_output && options.spread_band && !options.spread_neighbours;
  return heal;
}

// The planes around piece p (p-1 below it, p above it) among piece_count pieces.
void add_planes_around(int p, std::size_t piece_count, std::vector<int>& planes) {
  if (p > 0) planes.push_back(p - 1);
  if (static_cast<std::size_t>(p) + 1 < piece_count) planes.push_back(p);
}

// Partition and closure of one attempt, streamed: close() hands each piece on as soon as the caps
// on both its sides exist.
class ClosureStream {
 public:
  ClosureStream(const SurfaceMesh& input, const MeshOptions& options, PreparedPieces& prepared)
      : input_(input), options_(options), prepared_(prepared) {}

  // 1. Partition at the given planes (from choose_cut_planes).
  void partition(std::vector<CutPlane> planes) {
    prepared_.planes = std::move(planes);
    prepared_.split = split_at_planes(input_, prepared_.planes);
  }

  // 2. Closure, piece by piece; `ready` gets each piece as soon as it is closed. The caps come
  // from the scheduler when there is one (it may build them on other ranks), else from here.
  template <class Ready>
  void close(Ready ready, PieceScheduler* scheduler = nullptr) {
    const int k = prepared_.split.piece_count;
    CapBuilder builder(prepared_.split, prepared_.planes, options_.density);
    if (scheduler) {
      std::vector<CapBorder> borders;
      for (int p = 0; p + 1 < k; ++p) borders.push_back(builder.border(p));
      scheduler->share_caps(std::move(borders));
    }
    PieceAssembler assembler(prepared_.split);
    // The builder and the assembler hold what they need of the split's triangles now; seam
    // healing needs only those with a cut vertex. Freed before the pieces are meshed, while
    // rank 0's memory climbs to its peak.
    keep_seam_triangles(prepared_.split);
    std::vector<Cap> caps(static_cast<std::size_t>(std::max(k - 1, 0)));
    prepared_.pieces.clear();
    prepared_.pieces.reserve(static_cast<std::size_t>(k));  // submitted pieces must not move
    for (int p = 0; p < k; ++p) {
      if (p + 1 < k) {
        caps[p] = scheduler ? builder.place(p, scheduler->cap(p)) : builder.build(p);
        prepared_.cap_triangles += static_cast<std::int64_t>(caps[p].triangles.size());
      }
      prepared_.pieces.push_back(assembler.assemble(p, p > 0 ? &caps[p - 1] : nullptr, p + 1 < k ? &caps[p] : nullptr));
      if (p > 0) std::vector<Triangle>().swap(caps[p - 1].triangles);  // both its pieces have it now
      ready(prepared_.pieces.back());
    }
  }

 private:
  const SurfaceMesh& input_;
  const MeshOptions& options_;
  PreparedPieces& prepared_;
};

// One attempt's meshing: the pieces that did not fail, welded as they arrived, and the failures.
struct MeshedAttempt {
  MeshedAttempt(const MeshOptions& options, PreparedPieces& prepared)
      : welder(prepared.split, prepared.pieces), failures(prepared.pieces.size()) {
    if (prepared.pieces.size() > 1) welder.split_on_arrival(seam_band_spec(prepared.split, heal_options(options)));
    if (!options.scratch.empty()) {
      scratch = std::make_unique<ScratchBulks>(options.scratch);
      welder.keep_bulks_in(*scratch);
    }
  }
  std::unique_ptr<ScratchBulks> scratch;  // the bulks' files, in the paper's memory mode
  void note_bulks(MeshResult& result) const {
    if (scratch) result.scratch_bulks = scratch->stats().bulks, result.scratch_bytes = scratch->stats().bytes;
    result.bulks_where_meshed = bulks_where_meshed;
  }
  Welder welder;
  std::vector<std::optional<Failure>> failures;  // by piece
  double weld_seconds = 0;                       // welding while other pieces were still meshed
  std::int64_t bulks_where_meshed = 0;           // pieces split where they were meshed
};

// With one layer of band (the default without a quality bound) and several pieces, the pieces
// meshed on other ranks are split there and their bulks stay there (see split_where_meshed).
// Their Steiner points are numbered from 2^30 meanwhile: the closure is still adding cap points,
// so the first Steiner id is not known yet; the welder renumbers them.
BulkStore* split_on_other_ranks(const SplitSurface& split, const MeshOptions& options, PieceScheduler& scheduler) {
  constexpr std::int32_t kFirstSteinerThere = std::int32_t{1} << 30;
  const HealOptions heal = heal_options(options);
  BandSpec spec = seam_band_spec(split, heal);
  if (split.piece_count < 2 || spec.layers != 1 ||
      split.points.size() >= static_cast<std::size_t>(kFirstSteinerThere / 2))
    return nullptr;
  spec.split_point_count = kFirstSteinerThere;
  if (heal.remove_cap_points) spec.end_removed = kFirstSteinerThere;  // every cap point, however many
  return scheduler.split_where_meshed(spec);
}

// Meshes one attempt's pieces as they are closed and welds each result as it arrives. A closure
// failure still ends the scheduler's round (other ranks are waiting in it) before it propagates;
// so does a welding error, after the round.
MeshedAttempt close_and_mesh(const SurfaceMesh& input, const MeshOptions& options, std::vector<CutPlane> planes,
                             double partition_start, PreparedPieces& prepared, const ResultCache& cache,
                             PieceScheduler& scheduler, StageTimes* times) {
  StageTimer timer(times, partition_start);
  if (options.pieces > 1 && static_cast<int>(planes.size()) + 1 < options.pieces)
    log::warning("the model has only " + std::to_string(planes.size()) +
                 " distinct cut positions along the cut axis; using " + std::to_string(planes.size() + 1) +
                 " pieces instead of " + std::to_string(options.pieces));
  ClosureStream stream(input, options, prepared);
  stream.partition(std::move(planes));
  timer.lap("partition");
  if (scheduler.confirm_input()) timer.lap("input_check_wait");  // rank 1's check of the input
  std::vector<PieceTetMesh> reused;                              // results of earlier attempts
  std::vector<int> submitted;                                    // the piece of each submission
  scheduler.begin_round(options.tetgen);
  BulkStore* where_meshed = split_on_other_ranks(prepared.split, options, scheduler);
  try {
    stream.close(
        [&](const PieceSurface& piece) {
          if (auto cached = cache.find(piece)) {
            reused.push_back(std::move(*cached));
          } else {
            scheduler.submit(piece);
            submitted.push_back(piece.index);
          }
          scheduler.progress();
        },
        &scheduler);
  } catch (...) {
    scheduler.end_round_all();
    throw;
  }
  timer.lap("closure");
  MeshedAttempt attempt(options, prepared);
  std::exception_ptr weld_error;
  auto take = [&](int piece, PieceOutcome&& outcome) {
    if (outcome.failure) {
      attempt.failures[piece] = outcome.failure;
      return;
    }
    const double start = now_seconds();
    try {
      if (!weld_error && outcome.band) {
        if (!where_meshed) throw InternalError("piece " + std::to_string(piece) + " was split where nobody asked");
        attempt.welder.add_split(std::move(*outcome.band), *where_meshed);
        ++attempt.bulks_where_meshed;
      } else if (!weld_error) {
        attempt.welder.add(std::move(outcome.result));
      }
    } catch (...) {
      weld_error = std::current_exception();
    }
    // Meshed: its surface is not needed here any more (a failure elsewhere builds it again,
    // rebuilt_pieces); its global ids stay, for the welder.
    std::vector<Point3>().swap(prepared.pieces[piece].points);
    std::vector<Triangle>().swap(prepared.pieces[piece].triangles);
    attempt.weld_seconds += now_seconds() - start;
  };
  for (PieceTetMesh& result : reused) {
    const int piece = result.index;
    take(piece, PieceOutcome{std::move(result), std::nullopt});
  }
  scheduler.end_round(
      [&](std::size_t position, PieceOutcome&& outcome) { take(submitted[position], std::move(outcome)); });
  timer.lap("tetgen");
  if (weld_error) std::rethrow_exception(weld_error);
  return attempt;
}

// An attempt's partition and closure built again from its planes, with every piece's surface:
// close_and_mesh frees each piece's surface once its result is in, and a failure needs them (to
// name input faces, to keep the good results for the next attempt). The same input, planes and
// options give the same pieces; their global ids are compared to be sure.
PreparedPieces rebuilt_pieces(const SurfaceMesh& input, const MeshOptions& options, const PreparedPieces& meshed) {
  PreparedPieces again;
  ClosureStream stream(input, options, again);
  stream.partition(meshed.planes);
  stream.close([](const PieceSurface&) {});
  if (again.pieces.size() != meshed.pieces.size())
    throw InternalError("the partition built again has " + std::to_string(again.pieces.size()) + " pieces, not " +
                        std::to_string(meshed.pieces.size()));
  for (std::size_t p = 0; p < again.pieces.size(); ++p)
    if (again.pieces[p].global_ids != meshed.pieces[p].global_ids)
      throw InternalError("piece " + std::to_string(p) + " came out different when its partition was built again");
  return again;
}

// 4. Welds an attempt whose pieces all succeeded. The pieces' surfaces went as their results came
// in (close_and_mesh); their global ids, which the welder needed until now, go too, and the
// split's points move into the mesh.
TetMesh weld_attempt(Welder& welder, PreparedPieces& prepared) {
  for (PieceSurface& piece : prepared.pieces) std::vector<std::int32_t>().swap(piece.global_ids);
  return welder.finish(std::move(prepared.split.points));
}

// What makes a partition: the same planes, caps and tolerance give the same pieces and results.
struct Cuts {
  std::vector<CutPlane> planes;
  double density;
  std::string tolerance;
  bool operator==(const Cuts& o) const {
    if (planes.size() != o.planes.size() || density != o.density || tolerance != o.tolerance) return false;
    for (std::size_t i = 0; i < planes.size(); ++i)
      if (planes[i].normal != o.planes[i].normal || planes[i].offset != o.planes[i].offset) return false;
    return true;
  }
};
struct Partition {
  Cuts cuts;
  std::optional<AttemptFailure> failure;
};

// The whole input meshed as one piece, welded, with what made it.
struct OnePieceMesh {
  PreparedPieces prepared;
  TetMesh mesh;
  MeshOptions options;
};

// PARTET_INJECT_FAILURE=surface: the first piece fails as TetGen does on an input it cannot mesh
// without points on its surface, naming its first whole input triangle.
void inject_input_trouble(const PreparedPieces& prepared, std::vector<std::optional<Failure>>& failures) {
  for (std::size_t t = 0; !failures.empty() && t < prepared.pieces[0].triangles.size(); ++t) {
    const PieceSurface& piece = prepared.pieces[0];
    const Triangle& local = piece.triangles[t];
    if (std::any_of(local.begin(), local.end(),
                    [&](std::int32_t v) { return piece.global_ids[v] >= prepared.split.input_vertex_count; }))
      continue;
    failures[0] =
        Failure(FailureKind::changed_boundary, 0, {},
                "injected: TetGen changed the surface (PARTET_INJECT_FAILURE=surface)", {static_cast<std::int32_t>(t)});
    return;
  }
}

// The input faces a piece's failure names, when every face it names is a whole input triangle
// (no cut vertex, no cap point); empty otherwise.
std::vector<std::int64_t> input_faces_named(const Failure& failure, const PreparedPieces& prepared,
                                            const SurfaceMesh& input) {
  if (failure.faces.empty() || failure.piece < 0 || static_cast<std::size_t>(failure.piece) >= prepared.pieces.size())
    return {};
  const PieceSurface& piece = prepared.pieces[failure.piece];
  std::unordered_set<FaceKey, FaceKeyHash> wanted;
  for (std::int32_t t : failure.faces) {
    if (t < 0 || static_cast<std::size_t>(t) >= piece.triangles.size()) return {};
    Triangle global;
    for (int c = 0; c < 3; ++c) {
      global[c] = piece.global_ids[piece.triangles[t][c]];
      if (prepared.split.is_cut_vertex(global[c])) return {};
    }
    wanted.insert(FaceKey(global));
  }
  std::vector<std::int64_t> faces;
  for (std::size_t f = 0; f < input.triangles.size(); ++f)
    if (wanted.count(FaceKey(input.triangles[f]))) faces.push_back(static_cast<std::int64_t>(f));
  return faces;
}

// Input vertices keep their order in the output; the ones no triangle uses are dropped. Empty
// when that changes no id (see MeshResult::boundary_faces), unless `always`.
std::vector<Triangle> input_in_output_numbering(const SurfaceMesh& input, bool always) {
  const std::vector<char> used = used_vertices(input.points.size(), input.triangles);
  if (!always && std::find(used.begin(), used.end(), 0) == used.end()) return {};
  const std::vector<std::int32_t> new_id = compact_ids(used);
  std::vector<Triangle> faces;
  faces.reserve(input.triangles.size());
  for (const auto& t : input.triangles) faces.push_back({new_id[t[0]], new_id[t[1]], new_id[t[2]]});
  return faces;
}

// With points on the surface: keeps the input triangles that are boundary faces as they are and
// puts the other boundary faces (the parts of the split ones) after them.
void add_split_faces(MeshResult& result) {
  std::unordered_set<FaceKey, FaceKeyHash> boundary;
  std::vector<Triangle> faces;
  for (std::size_t t = 0; t < result.mesh.tets.size(); ++t)
    for (int j = 0; j < 4; ++j)
      if (result.mesh.neighbours[t][j] < 0) {
        faces.push_back(outward_face(result.mesh.tets[t], j));
        boundary.insert(FaceKey(faces.back()));
      }
  std::unordered_set<FaceKey, FaceKeyHash> whole;
  std::vector<Triangle> kept;
  std::int32_t input_points = 0;
  for (const Triangle& f : result.boundary_faces) {
    for (std::int32_t v : f) input_points = std::max(input_points, v + 1);
    if (boundary.count(FaceKey(f))) {
      kept.push_back(f);
      whole.insert(FaceKey(f));
    }
  }
  result.split_input_faces = static_cast<std::int64_t>(result.boundary_faces.size() - kept.size());
  result.split_faces_from = kept.size();
  std::unordered_set<std::int32_t> added;
  for (const Triangle& f : faces) {
    if (whole.count(FaceKey(f))) continue;
    kept.push_back(f);
    for (std::int32_t v : f)
      if (v >= input_points) added.insert(v);
  }
  result.surface_points_added = static_cast<std::int64_t>(added.size());
  result.boundary_faces = std::move(kept);
  if (result.split_input_faces == 0) result.split_faces_from = SIZE_MAX;
}

}  // namespace

namespace {

// The regions around the seams and the polish's neighbourhoods are meshed like pieces, on every
// rank; they keep their surfaces whole, whatever the pieces were allowed.
class RegionMeshers {
 public:
  RegionMeshers(const MeshOptions& options, PieceScheduler& scheduler)
      : scheduler_(scheduler), tetgen_(options.tetgen) {
    tetgen_.boundary_points = false;
  }
  RegionMesher seams() {
    return [this](const std::vector<PieceSurface>& regions) { return mesh(regions, tetgen_); };
  }
  // The rank that heals each chain (by place): those heal_chains hands them to (0: here).
  std::vector<int> chain_ranks(const std::vector<std::size_t>& tets) {
    std::vector<int> ranks;
    if (chains_on_ranks(tets.size())) ranks = scheduler_.chain_ranks(tets);
    if (ranks.size() != tets.size()) ranks.assign(tets.size(), 0);
    return ranks;
  }
  // The chains of the seams: on the ranks, each whole on one, when there are several of both;
  // else here, one after another, their regions meshed on every rank. Every chain heals, even
  // after one failed: the band's failure is the first in chain order, as on the ranks.
  std::vector<HealedChain> heal_chains(std::size_t count, const PieceScheduler::ChainCutter& cut_out,
                                       const HealOptions& options) {
    if (chains_on_ranks(count)) return scheduler_.heal_chains(count, cut_out, options, tetgen_);
    std::vector<HealedChain> healed;
    for (std::size_t i = 0; i < count; ++i) healed.push_back(heal_chain(weld_chain(cut_out(i)), options, seams()));
    return healed;
  }
  PolishMesher polish() {
    return [this](const std::vector<PieceSurface>& regions, const std::string& optimization) {
      TetgenOptions tetgen = tetgen_;
      tetgen.optimization = optimization;
      return mesh(regions, tetgen);
    };
  }

 private:
  bool chains_on_ranks(std::size_t count) const { return count > 1 && scheduler_.heals_chains_on_ranks(); }
  std::vector<PieceOutcome> mesh(const std::vector<PieceSurface>& regions, const TetgenOptions& tetgen) {
    scheduler_.begin_round(tetgen);
    for (const auto& region : regions) scheduler_.submit(region);
    return scheduler_.end_round_all();
  }
  PieceScheduler& scheduler_;
  TetgenOptions tetgen_;
};

// 6. After healing: the polish, and what the result tells about the partition.
void finish_healed(const SurfaceMesh& input, const PreparedPieces& prepared, const MeshOptions& options,
                   RegionMeshers& meshers, StageTimer& timer, MeshResult& result) {
  if (polishes(options) && !result.spread) {  // (spread_output is asked for without a polish)
    result.polish = polish_poor_tets(result.mesh, PolishOptions(), meshers.polish());
    timer.lap("polish");
  }
  result.boundary_faces = input_in_output_numbering(input, options.tetgen.boundary_points);
  if (options.tetgen.boundary_points) add_split_faces(result);
  result.cut_vertices_inserted = prepared.split.cut_vertex_count();
  result.planes = prepared.planes;
  result.cap_triangles = prepared.cap_triangles;
  result.pieces = static_cast<int>(prepared.pieces.size());
  result.axis = options.axis;
}

// The healed chains' figures together; throws the MeshingError of the first chain that failed.
SeamStats chains_stats(const std::vector<HealedChain>& healed) {
  SeamStats stats;
  stats.chains = static_cast<std::int64_t>(healed.size());
  for (const HealedChain& chain : healed) {
    if (chain.failure) throw MeshingError(*chain.failure);
    stats.cut_vertices_removed += chain.stats.cut_vertices_removed;
    stats.cap_points_removed += chain.stats.cap_points_removed;
    stats.regions += chain.stats.regions;
    stats.tets_in += chain.stats.tets_in;
    stats.tets_out += chain.stats.tets_out;
  }
  return stats;
}

// The welder's band parts by chain: where each chain's tets are, piece by piece (those kept where
// their pieces were split cut there, into the shares the welder gets from their stores).
struct BandByChains {
  SeamChainPlan plan;
  std::vector<BandPartPlace> places;                       // by piece
  std::vector<BandPartChains> pieces;                      // by piece, of the band parts here
  std::vector<std::vector<std::int32_t>> split_triangles;  // by chain
  std::vector<std::size_t> tets;                           // by chain
  std::vector<std::vector<std::int32_t>> split_points;     // by piece: those its band part uses (chain_split)
  std::vector<int> order;    // the chains, largest first, so that no rank is left with a large one at the end
  bool covers_band = false;  // every tet of the band parts is in a chain

  BandByChains(Welder& welder, const SplitSurface& split, const HealOptions& options) {
    const std::vector<BandPartLinks> links = welder.take_band_links();
    plan = seam_chain_plan(links, split, options);
    places = welder.band_part_places();
    split_triangles = chain_split_triangles(split, plan.planes);
    tets.assign(plan.planes.size(), 0);
    for (std::size_t p = 0; p < places.size(); ++p)
      for (std::size_t part = 0; part < links[p].tets.size(); ++part)
        if (plan.chain_of_part[p][part] >= 0)
          tets[static_cast<std::size_t>(plan.chain_of_part[p][part])] += static_cast<std::size_t>(links[p].tets[part]);
    covers_band = std::accumulate(tets.begin(), tets.end(), std::size_t{0}) == welder.band_tet_count();
    order.resize(tets.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return tets[a] > tets[b]; });
    pieces.resize(places.size());
    for (std::size_t p = 0; p < places.size(); ++p)
      if (welder.band_part_here(p)) pieces[p] = band_part_chains(welder.band_part(p), plan.chain_of_part[p]);
    for (std::size_t p = 0; p < places.size(); ++p)  // (once: each piece's part is in one or two chains)
      split_points.push_back(welder.band_split_points({p}));
  }
  // The band parts kept elsewhere cut into the chains' shares there, each sent to the rank that
  // heals its chain (meshers.chain_ranks).
  void cut_kept_shares(Welder& welder, RegionMeshers& meshers) const {
    std::vector<std::size_t> sizes;  // by place in order
    for (const int c : order) sizes.push_back(tets[static_cast<std::size_t>(c)]);
    const std::vector<int> ranks = meshers.chain_ranks(sizes);
    std::vector<int> healers(order.size());  // by chain
    for (std::size_t j = 0; j < order.size(); ++j) healers[static_cast<std::size_t>(order[j])] = ranks[j];
    welder.cut_kept_shares(plan.chain_of_part, order, healers);
  }
  // Chain c's split with its pieces' shares that this rank gives: those of the band parts here,
  // and, when it heals the chain here, those kept elsewhere (the chains must be asked for in
  // `order`); the rank that heals it elsewhere gets those from their owners.
  // (times: seconds taking the shares kept elsewhere, cutting those here, making the split)
  ChainShares chain(Welder& welder, std::size_t c, const SurfaceMesh& input, const SplitSurface& split,
                    const std::vector<Point3>& split_points, std::array<double, 3>& times) const {
    double start = now_seconds();
    std::vector<ChainShare> shares = welder.kept_shares(static_cast<int>(c));
    times[0] += now_seconds() - start;
    start = now_seconds();
    for (std::size_t p = 0; p < pieces.size(); ++p) {
      const auto& chains = pieces[p].chains;
      const auto it = std::lower_bound(chains.begin(), chains.end(), static_cast<int>(c));
      if (it == chains.end() || *it != static_cast<int>(c)) continue;
      shares.push_back(
          chain_share(welder.band_part(p), pieces[p], static_cast<std::size_t>(it - chains.begin()), places[p]));
    }
    times[1] += now_seconds() - start;
    start = now_seconds();
    ChainSplit split_of_chain = split_of(c, input, split, split_points);
    times[2] += now_seconds() - start;
    return chain_shares(std::move(shares), std::move(split_of_chain));
  }
  // Chain c's split, made here without its tets: from every split surface's point its pieces'
  // band parts use (rank 0 does not know which of them the chain's own tets use).
  ChainSplit split_of(std::size_t c, const SurfaceMesh& input, const SplitSurface& split,
                      const std::vector<Point3>& coordinates) const {
    std::vector<const std::vector<std::int32_t>*> parts;
    for (const std::size_t p : plan.pieces_in(static_cast<int>(c))) parts.push_back(&split_points[p]);
    return chain_split(split, input, coordinates, plan.planes[c], split_triangles[c], merged_split_points(parts));
  }
};

// Heals the band chain by chain (seam_chain_band.hpp), the chains found from the links of the
// pieces' band parts (the welder's): each chain's shares are gathered here, and the chain is
// welded from them and healed (on a rank of its own when there are several); the healed chains
// make the band, which is never
// welded when they hold all its tets (chain_links: then each chain's links, as its healing rank
// found them); so the band is the same however many ranks healed it.
// Throws the MeshingError of the first chain that failed; `band` is then as welded.
SeamStats heal_band_by_chains(Welder& welder, std::vector<Point3>&& split_points, TetMesh& band,
                              std::vector<BandChainLinks>& chain_links, const SurfaceMesh& input,
                              const SplitSurface& split, const HealOptions& options, RegionMeshers& meshers) {
  StepClock clock;
  const BandByChains by_chains(welder, split, options);
  by_chains.cut_kept_shares(welder, meshers);
  const std::size_t count = by_chains.plan.planes.size();
  clock.lap("chains");
  HealOptions heal = options;
  heal.chain_band_tets = !by_chains.covers_band;  // (the chains are then put back into the welded band)
  heal.keep_healed = options.keep_healed && options.chain_links && by_chains.covers_band;
  const std::vector<int>& order = by_chains.order;
  double gathering = 0;                  // the chains' shares, here (between the ranks' healing)
  std::array<double, 3> steps{0, 0, 0};  // of it: (taking those kept elsewhere, cutting those here, the splits)
  const PieceScheduler::ChainCutter cut_out = [&](std::size_t j) {
    const auto i = static_cast<std::size_t>(order[j]);
    const double start = now_seconds();
    ChainShares chain = by_chains.chain(welder, i, input, split, split_points, steps);
    gathering += now_seconds() - start;
    return chain;
  };
  std::vector<HealedChain> in_order = meshers.heal_chains(count, cut_out, heal);
  std::vector<HealedChain> healed(count);
  for (std::size_t j = 0; j < in_order.size(); ++j) healed[order[j]] = std::move(in_order[j]);
  clock.lap("healing");
  const bool failed = std::any_of(healed.begin(), healed.end(), [](const HealedChain& c) { return c.failure; });
  SeamStats stats;
  if (failed || !by_chains.covers_band) {  // (the band as welded for the whole mesh, or its tets outside the chains)
    if (heal.keep_healed) {                // (the chains healed elsewhere stayed there: they come back now)
      std::vector<std::pair<int, HealedChain>> kept = welder.take_kept_chains();
      log::info("took back the " + std::to_string(kept.size()) + " healed seam chains kept where they healed");
      for (auto& [j, chain] : kept) healed.at(static_cast<std::size_t>(order.at(j))) = std::move(chain);
    }
    if (std::any_of(healed.begin(), healed.end(), [](const HealedChain& c) { return c.kept_on >= 0; }))
      throw InternalError("a healed seam chain kept elsewhere did not come back");
    band = welder.weld_bands(std::move(split_points));
    stats = chains_stats(healed);
    std::vector<std::vector<std::int32_t>> chain_tets;  // each chain's tets in the band
    for (HealedChain& chain : healed) chain_tets.push_back(std::move(chain.band_tets));
    put_back_chains(band, chain_tets, std::move(healed));
  } else {
    band = welder.band_points(std::move(split_points));
    stats = chains_stats(healed);
    chain_links = add_healed_chains(band, std::move(healed), options.chain_links);
  }
  clock.lap("put back");
  log::debug("seam healing by " + std::to_string(count) + " chains of cuts: " + clock.steps +
             " (gathering the chains' shares " + std::to_string(gathering) + " s of the healing: taking those kept " +
             "elsewhere " + std::to_string(steps[0]) + " s, cutting those here " + std::to_string(steps[1]) +
             " s, the splits " + std::to_string(steps[2]) + " s)");
  return stats;
}

// 5. Heals the band alone; a part that failed (other than by running out of time or refining
// without end) may have needed to grow past the band's edge, so the seams heal over the whole
// mesh, as far as they need to grow.
TetMesh heal_band(const SurfaceMesh& input, const SplitSurface& split, std::vector<Point3>&& split_points,
                  Welder& welder, const HealOptions& options, RegionMeshers& meshers, SeamStats& stats,
                  std::shared_ptr<SpreadMesh>* spread, bool spread_neighbours) {
  const std::int64_t welded_tets = static_cast<std::int64_t>(welder.bulk_tet_count() + welder.band_tet_count());
  HealOptions on_band = options;
  on_band.drop_points = false;
  on_band.chain_links = spread && welder.keeps_bulks_elsewhere();  // (an assembled mesh needs no links)
  on_band.keep_healed = on_band.keep_healed && on_band.chain_links;
  TetMesh band;
  try {
    std::vector<BandChainLinks> chain_links;  // (when the chains make the band)
    stats = heal_band_by_chains(welder, std::move(split_points), band, chain_links, input, split, on_band, meshers);
    const double start = now_seconds();
    if (spread && welder.keeps_bulks_elsewhere()) {
      *spread = std::make_shared<SpreadMesh>(welder.spread(std::move(band), spread_neighbours, std::move(chain_links)));
      log::debug("left the mesh spread: " + std::to_string((*spread)->tets) + " tets, " +
                 std::to_string((*spread)->band_rows()) + " of them in the healed band, " +
                 std::to_string((*spread)->band_tets.size()) + " of those here, in " +
                 std::to_string(now_seconds() - start) + " s");
      return TetMesh();
    }
    TetMesh mesh = welder.assemble(std::move(band));
    log::debug("assembled the mesh: " + std::to_string(mesh.tets.size()) + " tets in " +
               std::to_string(now_seconds() - start) + " s");
    return mesh;
  } catch (const MeshingError& error) {
    const FailureKind kind = error.failure.kind;
    // (A region killed for memory, or out of it, would not fit better in a larger one.)
    if (kind == FailureKind::runaway || kind == FailureKind::timed_out || kind == FailureKind::killed ||
        kind == FailureKind::out_of_memory)
      throw;
    log::debug(std::string("seam healing goes on over the whole mesh: ") + error.what());
  }
  if (band.points.empty()) band = welder.weld_bands(std::move(split_points));  // (failed before the chains healed)
  TetMesh mesh = welder.assemble(std::move(band), false);
  stats = heal_seams(mesh, input, split, options, meshers.seams());
  stats.tets_out = std::count(mesh.piece.begin(), mesh.piece.end(), -1);
  stats.tets_in = welded_tets - (static_cast<std::int64_t>(mesh.tets.size()) - stats.tets_out);
  return mesh;
}

}  // namespace

MeshResult finish_mesh(const SurfaceMesh& input, const PreparedPieces& prepared, TetMesh&& welded,
                       const MeshOptions& options, PieceScheduler& scheduler, StageTimes* times) {
  StageTimer timer(times);
  MeshResult result;
  result.mesh = std::move(welded);
  RegionMeshers meshers(options, scheduler);
  result.seam = heal_seams(result.mesh, input, prepared.split, heal_options(options), meshers.seams());
  timer.lap("seam_healing");
  finish_healed(input, prepared, options, meshers, timer, result);
  return result;
}

bool assembles_to_check(double available_bytes, double needed_bytes, std::size_t tets) {
  // Half of int32's range: healing still adds tets to the count known here.
  constexpr std::size_t kMostTets = std::size_t{1} << 30;
  return needed_bytes > 0 && available_bytes >= needed_bytes && tets <= kMostTets;
}

namespace {

// Whether the mesh is left where its parts are (when it can be: heal_band), decided once the
// pieces are meshed (about `tets` of them), when this process's memory is known.
bool leaves_spread(const MeshOptions& options, std::size_t tets) {
  if (!options.spread_output) return false;
  const double needed = options.assemble_if_available_bytes;
  if (needed <= 0) return true;
  const double available = test_hooks::available_mb_for_check(available_memory_mb()) * 1048576.0;
  if (!assembles_to_check(available, needed, tets)) return true;
  log::debug("assembling the mesh to check it in memory: " + std::to_string(static_cast<long>(available / 1048576)) +
             " MB available, " + std::to_string(static_cast<long>(needed / 1048576)) + " MB needed");
  return false;
}

}  // namespace

MeshResult finish_mesh(const SurfaceMesh& input, PreparedPieces& prepared, Welder& welder, const MeshOptions& options,
                       PieceScheduler& scheduler, StageTimes* times) {
  StageTimer timer(times);
  MeshResult result;
  RegionMeshers meshers(options, scheduler);
  const bool spread = leaves_spread(options, welder.band_tet_count() + welder.bulk_tet_count());
  result.mesh = heal_band(input, prepared.split, std::move(prepared.split.points), welder, heal_options(options),
                          meshers, result.seam, spread ? &result.spread : nullptr, options.spread_neighbours);
  timer.lap("seam_healing");
  finish_healed(input, prepared, options, meshers, timer, result);
  return result;
}

void split_bands(Welder& welder, PreparedPieces& prepared, const MeshOptions& options) {
  const BandSpec spec = seam_band_spec(prepared.split, heal_options(options));
  for (PieceSurface& piece : prepared.pieces) std::vector<std::int32_t>().swap(piece.global_ids);
  welder.split_bands(spec);
  log::debug("seam bands: " + std::to_string(welder.band_tet_count()) + " of " +
             std::to_string(welder.band_tet_count() + welder.bulk_tet_count()) + " tets");
}

MeshResult finish_mesh(const SurfaceMesh& input, const PreparedPieces& prepared, std::vector<PieceTetMesh>&& results,
                       const MeshOptions& options, StageTimes* times) {
  StageTimer timer(times);
  PreparedPieces bands = prepared;  // its split's points move into the band mesh
  MeshedAttempt attempt(options, bands);
  for (auto& result : results) attempt.welder.add(std::move(result));
  split_bands(attempt.welder, bands, options);
  timer.lap("merge");
  BatchScheduler here([&](const std::vector<PieceSurface>& regions, const TetgenOptions& tetgen) {
    return mesh_pieces_here(regions, PieceRunner(tetgen, options.run));
  });
  MeshResult result = finish_mesh(input, bands, attempt.welder, options, here, times);
  attempt.note_bulks(result);
  return result;
}

std::vector<PieceOutcome> mesh_pieces_here(const std::vector<PieceSurface>& pieces, const PieceRunner& runner) {
  std::vector<PieceOutcome> outcomes;
  outcomes.reserve(pieces.size());
  for (const auto& piece : pieces) outcomes.push_back(runner.mesh(piece));
  return outcomes;
}

namespace {

// The pipeline with recovery, every input triangle kept whole (see mesh_with_retries).
MeshResult mesh_keeping_triangles(const SurfaceMesh& input, const MeshOptions& options, PieceScheduler& scheduler,
                                  StageTimes* times) {
  RetryPlan plan(input, options, available_memory_mb());
  ResultCache cache;
  bool input_checked = false;
  std::optional<OnePieceMesh> one_piece;  // the input meshed as one piece by the diagnosis
  std::optional<Partition> last;          // the partition that failed last
  for (;;) {
    if (plan.use_one_piece_mesh()) {
      MeshResult result =
          finish_mesh(input, one_piece->prepared, std::move(one_piece->mesh), one_piece->options, scheduler, times);
      result.retries = plan.take_records();
      return result;
    }
    const double partition_start = now_seconds();
    const MeshOptions attempt_options = plan.options();
    std::vector<CutPlane> planes;
    if (attempt_options.pieces != 1) {  // the sorted vertices are freed before the closure
      const AxisVertices along = sort_vertices_along(input, cut_axis(input, attempt_options.axis));
      planes =
          choose_cut_planes(input, along, attempt_options.pieces, attempt_options.plane_shifts, plan.fractions(along));
    }
    if (plan.fewer_cuts_than_pieces(planes.size())) continue;
    char density[32];
    std::snprintf(density, sizeof density, "%g", attempt_options.density);
    log::debug("attempt " + std::to_string(plan.attempt() + 1) + ": " + std::to_string(planes.size() + 1) +
               " pieces along " + axis_name(attempt_options.axis) + ", cap density " + density);
    const Cuts cuts{planes, attempt_options.density, attempt_options.tetgen.tolerance};
    if (last && last->cuts == cuts && last->failure) {  // no plane could move: the same pieces again
      plan.skip_repeat(*last->failure);
      continue;
    }
    AttemptFailure failed;
    try {
      PreparedPieces prepared;
      if (!plan.same_cuts_as_before()) cache.clear();
      MeshedAttempt attempt =
          close_and_mesh(input, attempt_options, std::move(planes), partition_start, prepared, cache, scheduler, times);
      if (test_hooks::every_cut_fails(attempt.failures.size()))
        for (std::size_t p = 0; p < attempt.failures.size(); ++p)
          attempt.failures[p] = Failure{FailureKind::changed_boundary,
                                        static_cast<int>(p),
                                        {},
                                        "injected: TetGen cannot recover a cap (PARTET_INJECT_FAILURE=cuts)"};
      std::optional<PreparedPieces> surfaces;  // the pieces' surfaces, built again when needed
      auto whole = [&]() -> const PreparedPieces& {
        if (!surfaces) surfaces = rebuilt_pieces(input, attempt_options, prepared);
        return *surfaces;
      };
      if (test_hooks::input_needs_surface_points()) inject_input_trouble(whole(), attempt.failures);
      for (std::size_t p = 0; p < attempt.failures.size(); ++p) {
        if (!attempt.failures[p]) continue;
        if (failed.failure.message.empty()) {
          failed.failure = *attempt.failures[p];
          if (!failed.failure.faces.empty()) failed.input_faces = input_faces_named(failed.failure, whole(), input);
        }
        add_planes_around(static_cast<int>(p), attempt.failures.size(), failed.planes);
      }
      if (failed.failure.message.empty()) {
        cache.clear();
        StageTimer timer(times);
        if (plan.diagnosing()) {  // kept, in case the other partitions fail too
          TetMesh welded = weld_attempt(attempt.welder, prepared);
          timer.lap("merge");
          one_piece = OnePieceMesh{std::move(prepared), std::move(welded), attempt_options};
          plan.diagnosis_passed();
          last.reset();
          continue;
        }
        split_bands(attempt.welder, prepared, attempt_options);
        timer.lap("merge");
        MeshResult result = finish_mesh(input, prepared, attempt.welder, attempt_options, scheduler, times);
        result.retries = plan.take_records();
        result.merge_seconds_overlapped = attempt.weld_seconds;
        attempt.note_bulks(result);
        return result;
      }
      for (std::size_t p = 0; p < attempt.failures.size(); ++p)  // the good results, for the next attempt
        if (!attempt.failures[p]) cache.keep(whole().pieces[p], attempt.welder.take_back(static_cast<int>(p)));
    } catch (const InputError&) {
      throw;
    } catch (const OptionError&) {
      throw;
    } catch (const MeshingError& e) {
      // From partition, closure, merge or seam healing; only the last knows its planes.
      failed.failure = e.failure;
      failed.planes = e.failure.planes;
    } catch (const Error& e) {
      failed.failure = Failure{FailureKind::other, -1, {}, e.what()};
    }
    // TetGen failing is often the input's fault (pieces are not checked for self-intersections
    // or the nesting of shells before TetGen): check the whole input once (throws InputError
    // naming input faces) before blaming the cuts.
    if (failed.failure.kind != FailureKind::injected && !input_checked) {
      check_no_self_intersections(input);
      check_shell_nesting(input);
      input_checked = true;
    }
    last = Partition{cuts, failed};
    plan.next(failed);
  }
}

// The input meshed as one piece, TetGen allowed points on its surface (its -p without -Y).
MeshResult mesh_splitting_triangles(const SurfaceMesh& input, const MeshOptions& options, PieceScheduler& scheduler,
                                    StageTimes* times) {
  MeshOptions one_piece = options;
  one_piece.pieces = 1;
  one_piece.plane_shifts.clear();
  one_piece.tetgen.boundary_points = true;
  one_piece.tetgen.tolerance.clear();
  PreparedPieces prepared;
  MeshedAttempt attempt =
      close_and_mesh(input, one_piece, {}, now_seconds(), prepared, ResultCache(), scheduler, times);
  if (attempt.failures.at(0)) {
    Failure failure = *attempt.failures[0];
    failure.piece = -1;
    failure.message = "TetGen cannot mesh this input even with points allowed on its surface: " + failure.message;
    throw InputMeshingError(failure);
  }
  StageTimer timer(times);
  TetMesh welded = weld_attempt(attempt.welder, prepared);
  timer.lap("merge");
  return finish_mesh(input, prepared, std::move(welded), one_piece, scheduler, times);
}

}  // namespace

MeshResult mesh_with_retries(const SurfaceMesh& input, const MeshOptions& options, PieceScheduler& scheduler,
                             StageTimes* times) {
  try {
    return mesh_keeping_triangles(input, options, scheduler, times);
  } catch (const InputMeshingError& e) {
    if (!options.allow_split_faces || !e.split_faces_may_help) throw;
    log::warning(std::string(e.what()) + "; meshing it as one piece with points allowed on its surface");
    MeshResult result = mesh_splitting_triangles(input, options, scheduler, times);
    result.retries.push_back({0, e.what(), {}});
    return result;
  }
}

MeshResult mesh_with_retries(const SurfaceMesh& input, const MeshOptions& options, const PieceMesher& mesher,
                             StageTimes* times) {
  BatchScheduler scheduler(mesher);
  return mesh_with_retries(input, options, scheduler, times);
}

MeshResult mesh_surface(const SurfaceMesh& input, const MeshOptions& options, StageTimes* times) {
  return mesh_with_retries(
      input, options,
      [&](const std::vector<PieceSurface>& pieces, const TetgenOptions& tetgen) {
        return mesh_pieces_here(pieces, PieceRunner(tetgen, options.run));
      },
      times);
}

}  // namespace partet
