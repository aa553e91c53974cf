#include "partet/piece_runner.hpp"

#include <algorithm>
#include <csignal>

#include "partet/errors.hpp"
#include "partet/serialize.hpp"
#include "partet/stage_timer.hpp"
#include "process/isolated_run.hpp"
#include "process/memory.hpp"

namespace partet {
namespace {

// Runs in the process that meshes: never throws, every failure becomes a reply.
std::string piece_reply(const PieceSurface& piece, const TetgenOptions& tetgen, const std::function<void()>& before) {
  PieceOutcome outcome;
  const double start = now_seconds(), resident_at_start = current_rss_mb();
  try {
    if (before) before();
    outcome.result = tetrahedralize_piece(piece, tetgen);
  } catch (const MeshingError& e) {
    outcome.failure = e.failure;
  } catch (const std::exception& e) {
    outcome.failure = Failure{FailureKind::other, piece.index, {}, e.what()};
  }
  outcome.seconds = now_seconds() - start;
  outcome.memory_mb = std::max(0.0, own_peak_rss_mb() - resident_at_start);
  return serialize_outcome(outcome);
}

// How an isolated run ended, as a failure of `what` (e.g. "meshing", "TetGen").
Failure process_failure(const IsolatedRun& run, int piece, const std::string& what) {
  switch (run.end()) {
    case ProcessEnd::crashed: {
      const int sig = run.signal();
      return {FailureKind::crashed,
              piece,
              {},
              what + " crashed (signal " + std::to_string(sig) +
                  (sig == SIGABRT ? ": an internal assertion failed)" : std::string(")"))};
    }
    case ProcessEnd::timed_out:
      return {FailureKind::timed_out,
              piece,
              {},
              what + " did not finish within " + std::to_string(static_cast<long long>(run.timeout_seconds())) + " s"};
    default:
      return {FailureKind::no_result, piece, {}, what + " ended without a result"};
  }
}

class InProcessJob : public PieceJob {
 public:
  explicit InProcessJob(std::string reply) : reply_(std::move(reply)) {}
  bool poll(int) override { return true; }
  std::string take_reply() override { return std::move(reply_); }

 private:
  std::string reply_;
};

class ChildProcessJob : public PieceJob {
 public:
  ChildProcessJob(const PieceSurface& piece, const TetgenOptions& tetgen, std::function<void()> before,
                  double timeout_seconds)
      : piece_(piece.index),
        run_([&piece, tetgen, before] { return piece_reply(piece, tetgen, before); }, timeout_seconds) {}
  bool poll(int wait_ms) override { return run_.poll(wait_ms); }
  std::string take_reply() override {
    run_.wait();
    if (run_.end() == ProcessEnd::finished) return run_.take_bytes();
    PieceOutcome outcome;
    outcome.failure = process_failure(run_, piece_, "meshing");
    return serialize_outcome(outcome);
  }

 private:
  int piece_;
  IsolatedRun run_;
};

}  // namespace

double default_tetgen_timeout(std::size_t triangles, const TetgenOptions& options) {
  return (5.0 + 1e-3 * static_cast<double>(triangles)) * (options.quality.empty() ? 1 : 10);
}

double PieceRunner::time_limit(const PieceSurface& piece) const {
  return run_.timeout_seconds > 0 ? run_.timeout_seconds : 10 + default_tetgen_timeout(piece.triangles.size(), tetgen_);
}

std::unique_ptr<PieceJob> PieceRunner::start(const PieceSurface& piece, std::function<void()> before) const {
  if (!run_.isolate) return std::make_unique<InProcessJob>(piece_reply(piece, tetgen_, before));
  return std::make_unique<ChildProcessJob>(piece, tetgen_, std::move(before), time_limit(piece));
}

std::string PieceRunner::mesh_to_reply(const PieceSurface& piece, std::function<void()> before) const {
  return start(piece, std::move(before))->take_reply();
}

PieceOutcome PieceRunner::mesh(const PieceSurface& piece) const { return deserialize_outcome(mesh_to_reply(piece)); }

LocalTetMesh PieceRunner::mesh_surface(const std::vector<Point3>& points,
                                       const std::vector<Triangle>& triangles) const {
  if (!run_.isolate) return mesh_closed_surface(points, triangles, tetgen_);
  const double limit =
      run_.timeout_seconds > 0 ? run_.timeout_seconds : default_tetgen_timeout(triangles.size(), tetgen_);
  IsolatedRun run(
      [&] {
        PieceOutcome outcome;
        try {
          outcome.result.mesh = mesh_closed_surface(points, triangles, tetgen_);
        } catch (const MeshingError& e) {
          outcome.failure = e.failure;
        } catch (const std::exception& e) {
          outcome.failure = Failure{FailureKind::other, -1, {}, e.what()};
        }
        return serialize_outcome(outcome);
      },
      limit);
  run.wait();
  if (run.end() != ProcessEnd::finished) throw MeshingError(process_failure(run, -1, "TetGen"));
  PieceOutcome outcome = deserialize_outcome(run.take_bytes());
  if (outcome.failure) throw MeshingError(*outcome.failure);
  return std::move(outcome.result.mesh);
}

}  // namespace partet
