// Where a piece is meshed: in this process, or in an isolated child process with time limits.
// The runner owns that decision, the process handling and the bytes a result travels as; the
// stages stay pure and the MPI layer only moves those bytes.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "partet/mesh_types.hpp"
#include "stages/piece.hpp"
#include "mesher/tetgen_mesher.hpp"

namespace partet {

struct RunOptions {
  // Run TetGen in a forked child process: Debian's TetGen can abort() (failed assert) or loop
  // forever on hard inputs; in a child that becomes an ordinary failure.
  bool isolate = true;
  // Seconds of CPU time before a run is given up (isolated runs only); 0 = a limit scaled with
  // the input size (5 s + 1 ms per triangle, x10 with quality refinement; +10 s for a whole
  // piece). Time spent waiting for a core does not count, up to kWallPerCpuSecond times the
  // limit in wall time.
  double timeout_seconds = 0;
  // Non-empty: a directory where every piece meshed is kept, and where a piece already meshed by
  // an earlier run of the same job is taken from instead of being meshed again
  // (piece_checkpoint.hpp). Seam regions are not kept.
  std::string checkpoint;
};

// A piece being meshed. Its reply is serialize_outcome's bytes.
class PieceJob {
 public:
  virtual ~PieceJob() = default;
  // Waits at most wait_ms; true once the reply is ready.
  virtual bool poll(int wait_ms) = 0;
  // Blocks until the reply is ready and returns it (once).
  virtual std::string take_reply() = 0;
  // Whether the reply was taken from the checkpoint (an earlier run meshed the piece).
  virtual bool from_checkpoint() const { return false; }
};

class PieceRunner {
 public:
  PieceRunner(TetgenOptions tetgen, RunOptions run) : tetgen_(std::move(tetgen)), run_(run) {}

  // True when jobs run in a child process, so the caller can do other work meanwhile.
  bool runs_in_background() const { return run_.isolate; }

  // Starts checking and meshing the piece; before() runs first, where the work runs (a test
  // hook). The piece must outlive the job.
  std::unique_ptr<PieceJob> start(const PieceSurface& piece, std::function<void()> before = {}) const;
  // Blocking forms: the reply bytes, or the outcome.
  std::string mesh_to_reply(const PieceSurface& piece, std::function<void()> before = {}) const;
  PieceOutcome mesh(const PieceSurface& piece) const;

  const TetgenOptions& tetgen() const { return tetgen_; }
  // The limits of an isolated run on this piece: its CPU time, and the wall time it may take
  // (so the longest a rank can take to answer for it), seconds.
  double time_limit(const PieceSurface& piece) const;
  double wall_limit(const PieceSurface& piece) const;

 private:
  // start without the checkpoint.
  std::unique_ptr<PieceJob> start_meshing(const PieceSurface& piece, std::function<void()> before) const;
  TetgenOptions tetgen_;
  RunOptions run_;
};

// The time limit used when RunOptions::timeout_seconds is 0, for a surface of that many
// triangles.
double default_tetgen_timeout(std::size_t triangles, const TetgenOptions& options);

// TetGen's peak memory per triangle of its surface, measured with and without a quality bound
// (armadillo_loop1, fertility: 2.4-2.8 KB).
constexpr double kTetgenKilobytesPerTriangle = 2.5;
// The most an isolated run may allocate for a surface of that many triangles: 64 MB plus
// kRunawayFactor times what TetGen needs. Past it the refinement is running away (a quality bound
// too tight to be met): the run fails then, instead of taking the machine's memory and time.
constexpr double kRunawayFactor = 10;
double memory_limit_mb(std::size_t triangles);

}  // namespace partet
