#include "partet/pipeline.hpp"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <unordered_map>

#include "partet/errors.hpp"
#include "partet/log.hpp"
#include "partet/merge.hpp"
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

// The sequence of partitions tried: which cut planes move after each failure, and how the caps
// get coarser.
class RetryPlan {
 public:
  explicit RetryPlan(const MeshOptions& options)
      : options_(options),
        // More pieces, more cuts that can cause trouble: a few more attempts per four pieces
        // (cheap, since a retry re-meshes only the pieces it changed).
        attempts_(std::max(1, options.max_attempts) + (std::max(options.pieces, 1) - 1) / 4) {
    options_.plane_shifts.assign(options.pieces > 1 ? static_cast<std::size_t>(options.pieces) - 1 : 0, 0);
  }

  const MeshOptions& options() const { return options_; }
  int attempt() const { return attempt_; }
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
    log::warning("the PCA cut planes kept failing; cutting along the coordinate axis nearest to it instead");
  }

  MeshOptions options_;
  int attempts_;
  int attempt_ = 0;
  std::vector<RetryRecord> records_;
};

// The planes around piece p (p-1 below it, p above it) among piece_count pieces.
void add_planes_around(int p, std::size_t piece_count, std::vector<int>& planes) {
  if (p > 0) planes.push_back(p - 1);
  if (static_cast<std::size_t>(p) + 1 < piece_count) planes.push_back(p);
}

// Partition and closure of one attempt, streamed: each piece is submitted as soon as the caps on
// both its sides exist (unless an earlier attempt meshed the same piece). Returns the outcomes in
// piece order once all are in.
class ClosureStream {
 public:
  ClosureStream(const SurfaceMesh& input, const MeshOptions& options, PreparedPieces& prepared)
      : input_(input), options_(options), prepared_(prepared) {}

  // 1. Partition.
  void partition() {
    prepared_.planes = choose_cut_planes(input_, options_.pieces, options_.axis, options_.plane_shifts);
    if (options_.balance == Balance::triangles && static_cast<int>(prepared_.planes.size()) + 1 == options_.pieces &&
        options_.pieces > 2)
      prepared_.planes = balanced_by_triangles(prepared_.planes);
    if (options_.pieces > 1 && static_cast<int>(prepared_.planes.size()) + 1 < options_.pieces)
      log::warning("the model has only " + std::to_string(prepared_.planes.size()) +
                   " distinct cut positions along the cut axis; using " + std::to_string(prepared_.planes.size() + 1) +
                   " pieces instead of " + std::to_string(options_.pieces));
    prepared_.split = split_at_planes(input_, prepared_.planes);
  }

  // 1b. Moves the planes so that the pieces' triangles, caps included, are about equal: a cap
  // belongs to both pieces beside it, and a cap across a thick part of the model adds many
  // triangles to two pieces. The caps are measured (a trial closure) and assumed to keep their
  // size where the planes move; each piece then gets the share of the input that makes its
  // total equal. Two such steps, keeping the best partition measured. (At K = 2 both pieces
  // have the one cap: nothing to do.)
  std::vector<CutPlane> balanced_by_triangles(std::vector<CutPlane> planes) const {
    std::vector<CutPlane> best = planes;
    double best_ratio = 0;
    for (int step = 0; step < 3; ++step) {
      const TrialSizes sizes = measure(planes);
      if (step == 0 || sizes.largest_ratio() < best_ratio) best = planes, best_ratio = sizes.largest_ratio();
      log::debug(format_balance(step, sizes.largest_ratio()));
      const std::vector<double> fractions = sizes.equalizing_fractions();
      if (step == 2 || fractions.empty()) break;
      planes = choose_cut_planes(input_, static_cast<int>(planes.size()) + 1, options_.axis, options_.plane_shifts,
                                 fractions);
      if (planes.size() != best.size()) break;
    }
    return best;
  }

  // Triangles of each piece's share of the input, and of each cap (cap[j + 1]: plane j's).
  struct TrialSizes {
    std::vector<double> input, cap;
    double total(int i) const { return input[i] + cap[i] + cap[i + 1]; }
    double mean() const {
      double sum = 0;
      for (std::size_t i = 0; i < input.size(); ++i) sum += total(static_cast<int>(i));
      return sum / static_cast<double>(input.size());
    }
    double largest_ratio() const {
      double largest = 0;
      for (std::size_t i = 0; i < input.size(); ++i) largest = std::max(largest, total(static_cast<int>(i)));
      return largest / mean();
    }
    // Cumulative input fractions below each plane that make every total equal; empty when the
    // caps alone would fill a piece.
    std::vector<double> equalizing_fractions() const {
      const int k = static_cast<int>(input.size());
      double all = 0;
      for (double v : input) all += v;
      const double each = mean();
      std::vector<double> fractions;
      double below = 0;
      for (int i = 0; i < k; ++i) {
        const double part = each - cap[i] - cap[i + 1];
        if (part < 0.1 * each) return {};
        below += part;
        if (i + 1 < k) fractions.push_back(below / all);
      }
      return fractions;
    }
  };

  TrialSizes measure(const std::vector<CutPlane>& planes) const {
    const int k = static_cast<int>(planes.size()) + 1;
    SplitSurface trial = split_at_planes(input_, planes);
    const std::vector<Cap> caps = build_caps(trial, planes, options_.density);
    TrialSizes sizes{std::vector<double>(static_cast<std::size_t>(k), 0),
                     std::vector<double>(static_cast<std::size_t>(k + 1), 0)};
    for (int j = 0; j + 1 < k; ++j) sizes.cap[static_cast<std::size_t>(j) + 1] = static_cast<double>(caps[j].triangles.size());
    for (std::int32_t p : trial.piece) sizes.input[p] += 1;
    return sizes;
  }

  static std::string format_balance(int step, double ratio) {
    char text[96];
    std::snprintf(text, sizeof text, "balancing triangles, step %d: the largest piece has %.3f x the mean", step, ratio);
    return text;
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

// Meshes one attempt's pieces as they are closed; outcomes in piece order. A closure failure
// still ends the scheduler's round (other ranks are waiting in it) before it propagates.
std::vector<PieceOutcome> close_and_mesh(const SurfaceMesh& input, const MeshOptions& options, PreparedPieces& prepared,
                                         const ResultCache& cache, PieceScheduler& scheduler, StageTimes* times) {
  StageTimer timer(times);
  ClosureStream stream(input, options, prepared);
  stream.partition();
  timer.lap("partition");
  std::vector<PieceOutcome> outcomes;
  std::vector<std::size_t> submitted;
  scheduler.begin_round(options.tetgen);
  try {
    stream.close([&](const PieceSurface& piece) {
      outcomes.emplace_back();
      if (auto cached = cache.find(piece)) {
        outcomes.back().result = std::move(*cached);
      } else {
        scheduler.submit(piece);
        submitted.push_back(outcomes.size() - 1);
      }
      scheduler.progress();
    });
  } catch (...) {
    scheduler.end_round();
    throw;
  }
  timer.lap("closure");
  std::vector<PieceOutcome> fresh = scheduler.end_round();
  timer.lap("tetgen");
  for (std::size_t i = 0; i < fresh.size(); ++i) outcomes[submitted[i]] = std::move(fresh[i]);
  return outcomes;
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
  stream.partition();
  timer.lap("partition");
  stream.close([](const PieceSurface&) {});
  timer.lap("closure");
  return prepared;
}

MeshResult finish_mesh(const SurfaceMesh& input, const PreparedPieces& prepared, std::vector<PieceTetMesh>&& results,
                       const MeshOptions& options, PieceScheduler& scheduler, StageTimes* times) {
  StageTimer timer(times);
  MeshResult result;
  result.mesh = weld(prepared.split.points, prepared.pieces, std::move(results));
  timer.lap("merge");
  // The regions around the seams are meshed like pieces, on every rank.
  const RegionMesher mesher = [&](const std::vector<PieceSurface>& regions) {
    scheduler.begin_round(options.tetgen);
    for (const auto& region : regions) scheduler.submit(region);
    return scheduler.end_round();
  };
  const HealOptions heal{heals(options), heals(options) && !options.tetgen.quality.empty() ? 1 : 0};
  result.seam = heal_seams(result.mesh, input, prepared.split, heal, mesher);
  timer.lap("seam_healing");
  result.boundary_faces = input_in_output_numbering(input);
  result.cut_vertices_inserted = prepared.split.cut_vertex_count();
  result.planes = prepared.planes;
  result.cap_triangles = prepared.cap_triangles;
  result.pieces = static_cast<int>(prepared.pieces.size());
  return result;
}

MeshResult finish_mesh(const SurfaceMesh& input, const PreparedPieces& prepared, std::vector<PieceTetMesh>&& results,
                       const MeshOptions& options, StageTimes* times) {
  BatchScheduler here([&](const std::vector<PieceSurface>& regions, const TetgenOptions& tetgen) {
    return mesh_pieces_here(regions, PieceRunner(tetgen, options.run));
  });
  return finish_mesh(input, prepared, std::move(results), options, here, times);
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
      std::vector<PieceOutcome> outcomes = close_and_mesh(input, plan.options(), prepared, cache, scheduler, times);
      for (std::size_t p = 0; p < outcomes.size(); ++p) {
        if (!outcomes[p].failure) continue;
        if (!failure) failure = outcomes[p].failure;
        add_planes_around(static_cast<int>(p), outcomes.size(), planes_to_move);
      }
      if (!failure) {
        cache.clear();
        std::vector<PieceTetMesh> results;
        results.reserve(outcomes.size());
        for (auto& o : outcomes) results.push_back(std::move(o.result));
        std::vector<PieceOutcome>().swap(outcomes);
        MeshResult result = finish_mesh(input, prepared, std::move(results), plan.options(), scheduler, times);
        result.retries = plan.take_records();
        return result;
      }
      if (!plan.last())  // keep the good results for the next attempt
        for (std::size_t p = 0; p < outcomes.size(); ++p)
          if (!outcomes[p].failure) cache.keep(prepared.pieces[p], std::move(outcomes[p].result));
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
