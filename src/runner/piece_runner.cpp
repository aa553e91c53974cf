#include "runner/piece_runner.hpp"

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <new>

#include "partet/errors.hpp"
#include "runner/serialize.hpp"
#include "common/format.hpp"
#include "common/stage_timer.hpp"
#include "runner/isolated_run.hpp"
#include "common/memory.hpp"
#include "common/log.hpp"
#include "runner/piece_checkpoint.hpp"

namespace partet {
namespace {

// What an allocation failing under the memory limit means.
Failure runaway(int piece, std::size_t triangles, double limit_mb) {
  return Failure(FailureKind::runaway, piece, {},
                 "TetGen needed more than " + std::to_string(static_cast<long long>(limit_mb)) +
                     " MB for a surface of " + std::to_string(triangles) +
                     " triangles, " + std::to_string(static_cast<int>(kRunawayFactor)) +
                     " times what such a surface needs: its refinement ran away");
}

// The room a meshing child has: limit_mb (partet's limit) or, when the process runs under a
// lower address-space limit it cannot raise (ulimit -v, a job's virtual memory limit), that one.
struct MemoryRoom {
  double limit_mb = 0;      // partet's (0: none)
  double inherited_mb = 0;  // what the inherited limit leaves (infinite: no limit)
  bool inherited_binds() const { return inherited_mb < limit_mb; }
};

// What running out of memory means: under partet's own limit, TetGen's refinement ran away;
// under a lower limit the process inherited, the piece is too large for it (more pieces help).
Failure out_of_memory(int piece, std::size_t triangles, const MemoryRoom& room) {
  if (room.inherited_binds())
    return Failure(FailureKind::out_of_memory, piece, {},
                   "TetGen ran out of memory under the address-space limit this process inherited (ulimit -v, "
                   "or a job's virtual memory limit: about " +
                       std::to_string(static_cast<long long>(std::max(0.0, room.inherited_mb))) + " MB left, for " +
                       std::to_string(triangles) + " triangles); more --pieces make each smaller, or raise the limit");
  if (room.limit_mb > 0) return runaway(piece, triangles, room.limit_mb);
  return Failure{FailureKind::other, piece, {}, "out of memory"};
}

// Runs in the process that meshes: never throws, every failure becomes a reply. With a memory
// limit (set by the isolated run) running out of memory is out_of_memory's failure.
std::string piece_reply(const PieceSurface& piece, const TetgenOptions& tetgen, const std::function<void()>& before,
                        const MemoryRoom& room) {
  PieceOutcome outcome;
  const double start = now_seconds(), resident_at_start = current_rss_mb();
  try {
    if (before) before();
    outcome.result = tetrahedralize_piece(piece, tetgen);
  } catch (const MeshingError& e) {
    outcome.failure = e.failure;
    if (room.limit_mb > 0 && e.failure.kind == FailureKind::tetgen_error && e.failure.message == kTetgenOutOfMemory)
      outcome.failure = out_of_memory(piece.index, piece.triangles.size(), room);
  } catch (const std::bad_alloc&) {
    outcome.failure = out_of_memory(piece.index, piece.triangles.size(), room);
  } catch (const std::exception& e) {
    outcome.failure = Failure{FailureKind::other, piece.index, {}, e.what()};
  }
  outcome.seconds = now_seconds() - start;
  outcome.memory_mb = std::max(0.0, own_peak_rss_mb() - resident_at_start);
  return serialize_outcome(outcome);
}

// The facets TetGen names in what it printed ("Found two facets intersect each other.", then
// "  1st: [a, b, c] #n" with n the facet's 1-based position): the surface's triangles n-1.
std::vector<std::int32_t> facets_named(const std::string& output, std::size_t triangles) {
  std::vector<std::int32_t> faces;
  for (std::size_t at = output.find("Found two"); at != std::string::npos; at = output.find("Found two", at + 1))
    for (std::size_t line = output.find('\n', at), k = 0; line != std::string::npos && k < 2; ++k) {
      const std::size_t next = output.find('\n', line + 1);
      const std::string text = output.substr(line + 1, next == std::string::npos ? std::string::npos : next - line - 1);
      const std::size_t hash = text.rfind('#');
      if (hash != std::string::npos) {
        const long n = std::strtol(text.c_str() + hash + 1, nullptr, 10);
        if (n >= 1 && static_cast<std::size_t>(n) <= triangles) faces.push_back(static_cast<std::int32_t>(n - 1));
      }
      line = next;
    }
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  return faces;
}

// Where an assertion failed, from its text ("...: int tetgenmesh::addsteiner4recoversegment(...):
// Assertion `0' failed."): " in TetGen's addsteiner4recoversegment", or "".
std::string assertion_place(const std::string& output) {
  const std::size_t assertion = output.find("Assertion");
  if (assertion == std::string::npos) return "";
  const std::size_t open = output.rfind('(', assertion), scope = output.rfind("::", open);
  if (open == std::string::npos || scope == std::string::npos || scope < output.rfind('\n', assertion) + 1) return "";
  return " in TetGen's " + output.substr(scope + 2, open - scope - 2);
}

// Seconds as a user reads them: whole ones, and "0.5" below one.
std::string whole_seconds(double seconds) { return format(seconds < 1 ? "%.1f" : "%.0f", seconds); }

// How an isolated run ended, as a failure of `what` (e.g. "meshing", "TetGen").
Failure process_failure(const IsolatedRun& run, int piece, const std::string& what) {
  switch (run.end()) {
    case ProcessEnd::crashed: {
      const int sig = run.signal();
      return {sig == SIGKILL ? FailureKind::killed : FailureKind::crashed,
              piece,
              {},
              what + " crashed (signal " + std::to_string(sig) +
                  (sig == SIGABRT   ? ": an internal assertion failed" + assertion_place(run.output()) + ")"
                   : sig == SIGKILL ? std::string(": killed from outside, most often by the out-of-memory killer when "
                                                  "the node, or a job's memory limit, has too little for the piece; "
                                                  "more --pieces make each smaller)")
                                    : std::string(")"))};
    }
    case ProcessEnd::timed_out:
      return {FailureKind::timed_out, piece, {},
              what + " did not finish within its " + whole_seconds(run.cpu_limit_seconds()) + " s of CPU time"};
    case ProcessEnd::stalled:
      return {FailureKind::timed_out, piece, {},
              what + " did not finish within " + whole_seconds(run.wall_limit_seconds()) + " s, having used " +
                  whole_seconds(run.cpu_seconds()) + " of its " + whole_seconds(run.cpu_limit_seconds()) +
                  " s of CPU time: its process was stopped, or the machine is overloaded"};
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
                  double cpu_seconds, double limit_mb)
      : piece_(piece.index),
        triangles_(piece.triangles.size()),
        room_{limit_mb, address_space_room_mb()},
        run_([&piece, tetgen, before, room = room_] { return piece_reply(piece, tetgen, before, room); }, cpu_seconds,
             limit_mb) {}
  bool poll(int wait_ms) override { return run_.poll(wait_ms); }
  std::string take_reply() override {
    run_.wait();
    PieceOutcome outcome;
    const bool near_limit = run_.peak_mb() > 0.8 * room_.limit_mb || (room_.inherited_binds() && run_.signal() != SIGKILL);
    if (run_.end() == ProcessEnd::crashed && near_limit) {
      // TetGen does not check every allocation: at the memory limit it may crash instead (under
      // an inherited limit, whose room the peak does not show, any crash but a kill counts).
      outcome.failure = out_of_memory(piece_, triangles_, room_);
    } else if (run_.end() != ProcessEnd::finished) {
      outcome.failure = process_failure(run_, piece_, "meshing");
    } else {
      std::string bytes = run_.take_bytes();
      outcome = deserialize_outcome(bytes);
      if (!outcome.failure || !outcome.failure->faces.empty()) return bytes;
    }
    // TetGen may have named the facets it stumbled on: the surface's triangles involved.
    outcome.failure->faces = facets_named(run_.output(), triangles_);
    return serialize_outcome(outcome);
  }

 private:
  int piece_;
  std::size_t triangles_;
  MemoryRoom room_;
  IsolatedRun run_;
};

// A piece an earlier run meshed, its reply taken from the checkpoint.
class CheckpointJob : public InProcessJob {
 public:
  using InProcessJob::InProcessJob;
  bool from_checkpoint() const override { return true; }
};

// A job whose result is kept in the checkpoint once it is taken.
class CheckpointedJob : public PieceJob {
 public:
  CheckpointedJob(std::unique_ptr<PieceJob> job, PieceCheckpoint checkpoint, std::string key, int index)
      : job_(std::move(job)), checkpoint_(std::move(checkpoint)), key_(std::move(key)), index_(index) {}
  bool poll(int wait_ms) override { return job_->poll(wait_ms); }
  std::string take_reply() override {
    std::string reply = job_->take_reply();
    checkpoint_.keep(key_, index_, reply);
    return reply;
  }

 private:
  std::unique_ptr<PieceJob> job_;
  PieceCheckpoint checkpoint_;
  std::string key_;
  int index_;
};

}  // namespace

double memory_limit_mb(std::size_t triangles) {
  return 64 + kRunawayFactor * kTetgenKilobytesPerTriangle * static_cast<double>(triangles) / 1024;
}

double default_tetgen_timeout(std::size_t triangles, const TetgenOptions& options) {
  return (5.0 + 1e-3 * static_cast<double>(triangles)) * (options.quality.empty() ? 1 : 10);
}

double PieceRunner::time_limit(const PieceSurface& piece) const {
  return run_.timeout_seconds > 0 ? run_.timeout_seconds : 10 + default_tetgen_timeout(piece.triangles.size(), tetgen_);
}

double PieceRunner::wall_limit(const PieceSurface& piece) const { return kWallPerCpuSecond * time_limit(piece); }

std::unique_ptr<PieceJob> PieceRunner::start(const PieceSurface& piece, std::function<void()> before) const {
  if (run_.checkpoint.empty() || piece.seam_region) return start_meshing(piece, std::move(before));
  const PieceCheckpoint checkpoint(run_.checkpoint);
  std::string key = PieceCheckpoint::key_of(piece, tetgen_);
  if (std::optional<std::string> reply = checkpoint.find(key, piece.index)) {
    log::info("piece " + std::to_string(piece.index) + " taken from the checkpoint (meshed by an earlier run)");
    return std::make_unique<CheckpointJob>(std::move(*reply));
  }
  return std::make_unique<CheckpointedJob>(start_meshing(piece, std::move(before)), checkpoint, std::move(key),
                                           piece.index);
}

std::unique_ptr<PieceJob> PieceRunner::start_meshing(const PieceSurface& piece, std::function<void()> before) const {
  if (!run_.isolate) return std::make_unique<InProcessJob>(piece_reply(piece, tetgen_, before, MemoryRoom{}));
  return std::make_unique<ChildProcessJob>(piece, tetgen_, std::move(before), time_limit(piece),
                                           memory_limit_mb(piece.triangles.size()));
}

std::string PieceRunner::mesh_to_reply(const PieceSurface& piece, std::function<void()> before) const {
  return start(piece, std::move(before))->take_reply();
}

PieceOutcome PieceRunner::mesh(const PieceSurface& piece) const { return deserialize_outcome(mesh_to_reply(piece)); }

}  // namespace partet
