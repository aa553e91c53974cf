#include "partet/pipeline.hpp"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <optional>
#include <unordered_map>

#include "partet/errors.hpp"
#include "partet/log.hpp"
#include "partet/merge.hpp"
#include "partet/piece_cost.hpp"
#include "partet/validate.hpp"
#include "topology.hpp"

namespace partet {
namespace {

// Results of pieces meshed in earlier attempts, by content: a piece identical to one already
// meshed (same points and triangles in the same local order) reuses that result, so a retry
// re-meshes only the pieces its moved planes changed. TetGen is deterministic, so the output
// is the same either way.
class ResultCache {
 public:
  std::optional<PieceTetMesh> find(const PieceSurface& piece) const {
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
    std::uint64_t h = 1469598103934665603ull;
    auto mix = [&h](const void* data, std::size_t bytes) {
      const auto* b = static_cast<const unsigned char*>(data);
      for (std::size_t i = 0; i < bytes; ++i) h = (h ^ b[i]) * 1099511628211ull;
    };
    if (!piece.points.empty()) mix(piece.points.data(), piece.points.size() * sizeof(Point3));
    if (!piece.triangles.empty()) mix(piece.triangles.data(), piece.triangles.size() * sizeof(Triangle));
    return h;
  }
  std::unordered_map<std::uint64_t, Entry> entries_;
};

// Where the planes go for these options: the fractions of the vertices below each plane that
// balance the pieces' estimated costs, or none (equal vertex counts).
std::vector<double> plane_fractions(const SurfaceMesh& input, const MeshOptions& options, double density) {
  if (options.balance != Balance::cost) return {};
  return cost_balanced_fractions(input, cut_axis(input, options.axis), options.pieces, density);
}

// The sequence of partitions tried: which cut planes move after each failure, and how the caps
// get coarser.
class RetryPlan {
 public:
  explicit RetryPlan(const MeshOptions& options)
      : options_(options),
        first_density_(options.density),
        // More pieces, more cuts that can cause trouble: a few more attempts per four pieces
        // (cheap, since a retry re-meshes only the pieces it changed).
        attempts_(std::max(1, options.max_attempts) + (std::max(options.pieces, 1) - 1) / 4) {
    options_.plane_shifts.assign(options.pieces > 1 ? static_cast<std::size_t>(options.pieces) - 1 : 0, 0);
  }

  const MeshOptions& options() const { return options_; }
  int attempt() const { return attempt_; }
  // Where the planes aim, computed once per cut axis with the caps first asked for: retries lower
  // the cap density, but must move only the planes they name.
  const std::vector<double>& fractions(const SurfaceMesh& input) {
    if (!fractions_known_) fractions_ = plane_fractions(input, options_, first_density_), fractions_known_ = true;
    return fractions_;
  }
  bool last() const { return attempt_ + 1 >= attempts_; }
  std::vector<int> all_planes() const {
    std::vector<int> planes(options_.plane_shifts.size());
    for (std::size_t j = 0; j < planes.size(); ++j) planes[j] = static_cast<int>(j);
    return planes;
  }

  // TetGen's coplanarity tolerance is relative to the model's size: for a valid input it called
  // self-intersecting or too close (a very thin solid), later attempts use a tiny one. True
  // when the options changed.
  bool tighten_tolerance(const Failure& failure) {
    if ((failure.kind != FailureKind::self_intersection && failure.kind != FailureKind::too_close) ||
        !options_.tetgen.tolerance.empty())
      return false;
    options_.tetgen.tolerance = "1e-16";
    log::warning(
        "the input is valid but TetGen took part of it for self-intersecting or degenerate; "
        "retrying with a tighter tolerance");
    return true;
  }

  // Moves the planes for the next attempt (none when only the options changed); throws the
  // failure when no attempt is left.
  void next(const Failure& failure, std::vector<int> planes, bool options_changed) {
    std::sort(planes.begin(), planes.end());
    planes.erase(std::unique(planes.begin(), planes.end()), planes.end());
    if (last() || (planes.empty() && !options_changed)) {
      Failure final = failure;
      final.message = failure.text() + (attempt_ > 0 ? " (after " + std::to_string(attempt_ + 1) + " partitions)" : "");
      final.piece = -1;
      throw MeshingError(final);
    }
    std::string note = "attempt " + std::to_string(attempt_ + 1) + " failed: " + failure.text();
    if (!planes.empty()) note += "; moving cut plane(s)";
    for (int j : planes) note += " " + std::to_string(j);
    // From the third attempt on, also simplify the caps: fewer interior cap points leave TetGen
    // less to recover on the cap (the last attempt uses none).
    if (attempt_ >= 1 && options_.density > 0) {
      options_.density = attempt_ + 2 >= attempts_ ? 0.0 : options_.density / 2;
      char density[32];
      std::snprintf(density, sizeof density, "%g", options_.density);
      note += std::string(" and lowering the cap density to ") + density;
    }
    log::warning(note + "; retrying");
    records_.push_back({attempt_, failure.text(), planes});
    for (int j : planes) ++options_.plane_shifts[j];
    ++attempt_;
    fall_back_to_coordinate_axis();
  }

  std::vector<RetryRecord> take_records() { return std::move(records_); }

 private:
  // Crossings on a PCA plane are rounded off it, so its caps are only nearly planar and TetGen
  // can fail to recover them however the planes move: after half the attempts, cut along the
  // coordinate axis nearest the PCA axis instead (exactly planar caps), from fresh planes.
  void fall_back_to_coordinate_axis() {
    if (options_.axis != CutAxis::pca || attempt_ < attempts_ / 2) return;
    options_.axis = CutAxis::coordinate_near_pca;
    std::fill(options_.plane_shifts.begin(), options_.plane_shifts.end(), 0);
    fractions_known_ = false;
    log::warning("the PCA cut planes kept failing; cutting along the coordinate axis nearest to it instead");
  }

  MeshOptions options_;
  double first_density_;  // the cap density asked for
  std::vector<double> fractions_;
  bool fractions_known_ = false;
  int attempts_;
  int attempt_ = 0;
  std::vector<RetryRecord> records_;
};

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

  // 1. Partition: the planes go where the pieces' estimated costs are equal (fractions of the
  // vertices below each plane, from cost_balanced_fractions) or, when fractions is empty, where
  // their vertex counts are.
  void partition(const std::vector<double>& fractions) {
    prepared_.planes = choose_cut_planes(input_, options_.pieces, options_.axis, options_.plane_shifts, fractions);
    if (options_.pieces > 1 && static_cast<int>(prepared_.planes.size()) + 1 < options_.pieces)
      log::warning("the model has only " + std::to_string(prepared_.planes.size()) +
                   " distinct cut positions along the cut axis; using " + std::to_string(prepared_.planes.size() + 1) +
                   " pieces instead of " + std::to_string(options_.pieces));
    prepared_.split = split_at_planes(input_, prepared_.planes);
  }

  // 2. Closure, piece by piece; `ready` gets each piece as soon as it is closed.
  template <class Ready>
  void close(Ready ready) {
    const int k = prepared_.split.piece_count;
    CapBuilder builder(prepared_.split, prepared_.planes, options_.density);
    PieceAssembler assembler(prepared_.split);
    std::vector<Cap> caps(static_cast<std::size_t>(std::max(k - 1, 0)));
    prepared_.pieces.clear();
    prepared_.pieces.reserve(static_cast<std::size_t>(k));  // submitted pieces must not move
    for (int p = 0; p < k; ++p) {
      if (p + 1 < k) {
        caps[p] = builder.build(p);
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
  Welder welder;
  std::vector<std::optional<Failure>> failures;  // by piece
  double weld_seconds = 0;                        // welding while other pieces were still meshed
};

// Meshes one attempt's pieces as they are closed and welds each result as it arrives. A closure
// failure still ends the scheduler's round (other ranks are waiting in it) before it propagates;
// so does a welding error, after the round.
MeshedAttempt close_and_mesh(const SurfaceMesh& input, const MeshOptions& options, const std::vector<double>& fractions,
                             PreparedPieces& prepared, const ResultCache& cache, PieceScheduler& scheduler,
                             StageTimes* times) {
  StageTimer timer(times);
  ClosureStream stream(input, options, prepared);
  stream.partition(fractions);
  timer.lap("partition");
  std::vector<PieceTetMesh> reused;  // results of earlier attempts
  std::vector<int> submitted;        // the piece of each submission
  scheduler.begin_round(options.tetgen);
  try {
    stream.close([&](const PieceSurface& piece) {
      if (auto cached = cache.find(piece)) {
        reused.push_back(std::move(*cached));
      } else {
        scheduler.submit(piece);
        submitted.push_back(piece.index);
      }
      scheduler.progress();
    });
  } catch (...) {
    scheduler.end_round_all();
    throw;
  }
  timer.lap("closure");
  MeshedAttempt attempt{Welder(prepared.split, prepared.pieces), std::vector<std::optional<Failure>>(prepared.pieces.size())};
  std::exception_ptr weld_error;
  auto take = [&](int piece, PieceOutcome&& outcome) {
    if (outcome.failure) {
      attempt.failures[piece] = outcome.failure;
      return;
    }
    const double start = now_seconds();
    try {
      if (!weld_error) attempt.welder.add(std::move(outcome.result));
    } catch (...) {
      weld_error = std::current_exception();
    }
    attempt.weld_seconds += now_seconds() - start;
  };
  for (PieceTetMesh& result : reused) {
    const int piece = result.index;
    take(piece, PieceOutcome{std::move(result), std::nullopt});
  }
  scheduler.end_round([&](std::size_t position, PieceOutcome&& outcome) { take(submitted[position], std::move(outcome)); });
  timer.lap("tetgen");
  if (weld_error) std::rethrow_exception(weld_error);
  return attempt;
}

// Input vertices keep their order in the output; the ones no triangle uses are dropped.
std::vector<Triangle> input_in_output_numbering(const SurfaceMesh& input) {
  const std::vector<std::int32_t> new_id = compact_ids(used_vertices(input.points.size(), input.triangles));
  std::vector<Triangle> faces;
  faces.reserve(input.triangles.size());
  for (const auto& t : input.triangles) faces.push_back({new_id[t[0]], new_id[t[1]], new_id[t[2]]});
  return faces;
}

}  // namespace

PreparedPieces prepare_pieces(const SurfaceMesh& input, const MeshOptions& options, StageTimes* times) {
  StageTimer timer(times);
  PreparedPieces prepared;
  ClosureStream stream(input, options, prepared);
  stream.partition(plane_fractions(input, options, options.density));
  timer.lap("partition");
  stream.close([](const PieceSurface&) {});
  timer.lap("closure");
  return prepared;
}

MeshResult finish_mesh(const SurfaceMesh& input, const PreparedPieces& prepared, TetMesh&& welded,
                       const MeshOptions& options, PieceScheduler& scheduler, StageTimes* times) {
  StageTimer timer(times);
  MeshResult result;
  result.mesh = std::move(welded);
  // The regions around the seams and the polish's neighbourhoods are meshed like pieces, on
  // every rank.
  auto mesh_regions = [&](const std::vector<PieceSurface>& regions, const TetgenOptions& tetgen) {
    scheduler.begin_round(tetgen);
    for (const auto& region : regions) scheduler.submit(region);
    return scheduler.end_round_all();
  };
  const RegionMesher mesher = [&](const std::vector<PieceSurface>& regions) {
    return mesh_regions(regions, options.tetgen);
  };
  const HealOptions heal{heals(options), heals(options) && !options.tetgen.quality.empty() ? 2 : 0};
  result.seam = heal_seams(result.mesh, input, prepared.split, heal, mesher);
  timer.lap("seam_healing");
  if (polishes(options)) {
    const PolishMesher polisher = [&](const std::vector<PieceSurface>& regions, const std::string& optimization) {
      TetgenOptions tetgen = options.tetgen;
      tetgen.optimization = optimization;
      return mesh_regions(regions, tetgen);
    };
    result.polish = polish_poor_tets(result.mesh, PolishOptions(), polisher);
    timer.lap("polish");
  }
  result.boundary_faces = input_in_output_numbering(input);
  result.cut_vertices_inserted = prepared.split.cut_vertex_count();
  result.planes = prepared.planes;
  result.cap_triangles = prepared.cap_triangles;
  result.pieces = static_cast<int>(prepared.pieces.size());
  return result;
}

MeshResult finish_mesh(const SurfaceMesh& input, const PreparedPieces& prepared, std::vector<PieceTetMesh>&& results,
                       const MeshOptions& options, StageTimes* times) {
  StageTimer timer(times);
  TetMesh welded = weld(prepared.split, prepared.pieces, std::move(results));
  timer.lap("merge");
  BatchScheduler here([&](const std::vector<PieceSurface>& regions, const TetgenOptions& tetgen) {
    return mesh_pieces_here(regions, PieceRunner(tetgen, options.run));
  });
  return finish_mesh(input, prepared, std::move(welded), options, here, times);
}

std::vector<PieceOutcome> mesh_pieces_here(const std::vector<PieceSurface>& pieces, const PieceRunner& runner) {
  std::vector<PieceOutcome> outcomes;
  outcomes.reserve(pieces.size());
  for (const auto& piece : pieces) outcomes.push_back(runner.mesh(piece));
  return outcomes;
}

MeshResult mesh_with_retries(const SurfaceMesh& input, const MeshOptions& options, PieceScheduler& scheduler,
                             StageTimes* times) {
  RetryPlan plan(options);
  ResultCache cache;
  bool input_checked = false;
  for (;;) {
    std::optional<Failure> failure;
    std::vector<int> planes_to_move;
    try {
      PreparedPieces prepared;
      MeshedAttempt attempt = close_and_mesh(input, plan.options(), plan.fractions(input), prepared, cache, scheduler, times);
      for (std::size_t p = 0; p < attempt.failures.size(); ++p) {
        if (!attempt.failures[p]) continue;
        if (!failure) failure = attempt.failures[p];
        add_planes_around(static_cast<int>(p), attempt.failures.size(), planes_to_move);
      }
      if (!failure) {
        cache.clear();
        StageTimer timer(times);
        TetMesh welded = attempt.welder.finish();
        timer.lap("merge");
        MeshResult result = finish_mesh(input, prepared, std::move(welded), plan.options(), scheduler, times);
        result.retries = plan.take_records();
        result.merge_seconds_overlapped = attempt.weld_seconds;
        return result;
      }
      if (!plan.last())  // keep the good results for the next attempt
        for (std::size_t p = 0; p < attempt.failures.size(); ++p)
          if (!attempt.failures[p]) cache.keep(prepared.pieces[p], attempt.welder.take_back(static_cast<int>(p)));
    } catch (const InputError&) {
      throw;
    } catch (const OptionError&) {
      throw;
    } catch (const MeshingError& e) {
      // From partition, closure, merge or seam healing; only the last knows its planes.
      failure = e.failure;
      planes_to_move = e.failure.planes;
    } catch (const Error& e) {
      failure = Failure{FailureKind::other, -1, {}, e.what()};
    }
    // TetGen failing is often the input's fault (pieces are not checked for self-intersections
    // or the nesting of shells before TetGen): check the whole input once (throws InputError
    // naming input faces) before blaming the cuts.
    if (failure->kind != FailureKind::injected && !input_checked) {
      check_no_self_intersections(input);
      check_shell_nesting(input);
      input_checked = true;
    }
    const bool options_changed = plan.tighten_tolerance(*failure);
    if (planes_to_move.empty() && !options_changed) planes_to_move = plan.all_planes();
    plan.next(*failure, planes_to_move, options_changed);
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
