#include "mpi/driver.hpp"

#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <sstream>
#include <thread>

#include <fcntl.h>
#include <unistd.h>

#include "common/awake_clock.hpp"
#include "common/log.hpp"
#include "common/memory.hpp"
#include "common/parallel.hpp"
#include "common/paths.hpp"
#include "common/test_hooks.hpp"
#include "io/buffered_file.hpp"
#include "io/output_set.hpp"
#include "io/parallel_hdf5.hpp"
#include "io/scratch_bulks.hpp"
#include "io/tetgen_files.hpp"
#include "io/write_surface.hpp"
#include "job/root_run.hpp"
#include "mpi/heartbeat.hpp"
#include "mpi/transport.hpp"
#include "partet/errors.hpp"
#include "runner/interrupts.hpp"
#include "runner/isolated_run.hpp"
#include "runner/serialize.hpp"
#include "stages/input_share.hpp"
#include "stages/validate.hpp"

namespace partet::mpi {
namespace {

constexpr int kTagPiece = 1;
constexpr int kTagReply = 2;
constexpr int kTagBlock = 3;
constexpr int kTagVerdict = 5;   // rank 1's verdict on the input
constexpr int kTagFindings = 6;  // another checking rank's findings, to rank 1
constexpr int kTagBulk = 8;      // a kept bulk, back to rank 0
// How long rank 0 sleeps between looks at MPI when idle: the pause doubles from the shortest to
// the longest while nothing happens, so replies to small regions (seams, polish) are taken at
// once and long pieces still leave the core to the TetGen processes.
constexpr std::chrono::microseconds kShortestIdle{50}, kLongestIdle{5000};
enum Command : int { kDone = 0, kMeshPieces = 1, kSendBulk = 2, kNumberBulks = 3 };

// A stopped or dead rank must end the job within a bounded time, naming it. Rank 0 allows a
// worker a piece's own wall time limit (PieceRunner::wall_limit) plus kReplyGraceSeconds to answer, and kWorkerSeconds
// for anything else (taking a message, joining an agreement); while the worker's TetGen process is at work, its
// heartbeats must not stop for kSilentSeconds (heartbeat.hpp). A worker allows rank 0, which may merge and write for
// long, kRootSeconds between messages.
constexpr double kReplyGraceSeconds = 10;
constexpr double kWorkerSeconds = 120;
constexpr double kRootSeconds = 3600;

// The communicator of the job this process runs: MPI_COMM_WORLD for the command, the caller's
// for the library (mesh_collective). One job at a time per process (TetGen keeps global state),
// so one variable is enough.
MPI_Comm current_comm = MPI_COMM_WORLD;
MPI_Comm job_comm() { return current_comm; }
class UseComm {
 public:
  explicit UseComm(MPI_Comm comm) : saved_(current_comm) { current_comm = comm; }
  ~UseComm() { current_comm = saved_; }
  UseComm(const UseComm&) = delete;
  UseComm& operator=(const UseComm&) = delete;

 private:
  MPI_Comm saved_;
};

// Ends the whole job now: a rank stopped answering.
[[noreturn]] void abort_job(const std::string& message) {
  log::error(message + "; ending the job");
  MPI_Abort(job_comm(), 1);
  std::abort();  // MPI_Abort does not return
}

int my_rank() {
  int rank = 0;
  MPI_Comm_rank(job_comm(), &rank);
  return rank;
}

// How long this rank waits for the others in a collective step.
double collective_limit() { return my_rank() == 0 ? kWorkerSeconds : kRootSeconds; }

// Runs a collective step; a rank that does not join in time ends the job.
template <class Step>
auto bounded(Step step) {
  try {
    return step();
  } catch (const Stalled&) {
    abort_job(my_rank() == 0 ? "a worker rank did not join the agreement within " +
                                   std::to_string(static_cast<int>(kWorkerSeconds)) + " s (stopped or dead?)"
                             : "rank 0 has sent nothing for " + std::to_string(static_cast<int>(kRootSeconds)) +
                                   " s (stopped or dead?)");
  }
}

// Every rank learns whether all ranks succeeded.
bool agree(bool ok_here) {
  return bounded([&] { return all_true(ok_here, job_comm(), collective_limit()); });
}

void broadcast(Command command) {
  bounded([&] { return broadcast_int(command, 0, job_comm(), collective_limit()); });
}

Command receive_command() {
  return static_cast<Command>(bounded([&] { return broadcast_int(kDone, 0, job_comm(), collective_limit()); }));
}

// Rank 0's text to every rank.
std::string broadcast_text(const std::string& text) {
  const int size =
      bounded([&] { return broadcast_int(static_cast<int>(text.size()), 0, job_comm(), collective_limit()); });
  std::string received = text;
  received.resize(static_cast<std::size_t>(size));
  MPI_Bcast(received.data(), size, MPI_CHAR, 0, job_comm());
  return received;
}

// How long rank 1 waits for the other checking ranks' findings on an input of `faces` faces:
// kWorkerSeconds + 1 s per million faces (rank 0 waits as long for rank 1's verdict on 2 ranks,
// twice as long on more).
double input_check_limit(std::size_t faces) {
  return test_hooks::verdict_wait_seconds(kWorkerSeconds + 1e-6 * static_cast<double>(faces));
}

// Adds the seconds an object lives to a total.
struct AddSeconds {
  double& total;
  double start = now_seconds();
  ~AddSeconds() { total += now_seconds() - start; }
};

// Writes the piece's closed surface as DIR/piece_<i>.off, for looking at a failing piece.
// Triangulates a cap on this rank, its PartitionError kept as the outcome's failure, and counts
// it in stats. `before` runs first, inside the same handling (a test hook).
CapOutcome triangulated(const CapBorder& border, RankStats& stats, const std::function<void()>& before = {}) {
  const double start = now_seconds();
  CapOutcome outcome;
  try {
    if (before) before();
    outcome.shape = triangulate_cap(border);
  } catch (const PartitionError& e) {
    outcome.failure = e.failure;
  }
  outcome.seconds = now_seconds() - start;
  stats.cap_seconds += outcome.seconds;
  stats.caps += 1;
  return outcome;
}

void dump_piece(const MeshJob& job, const PieceSurface& piece) {
  if (job.dump_pieces_dir.empty()) return;
  write_off(SurfaceMesh{piece.points, piece.triangles},
            job.dump_pieces_dir + "/piece_" + std::to_string(piece.index) + ".off");
}

// The bulks of the pieces split where they were meshed (split_where_meshed), kept by the ranks
// that meshed them until the welder needs them. Before the assembly rank 0 broadcasts
// kNumberBulks and the numbering's shares of the kept bulks: each owner numbers its own at once
// (while rank 0 numbers those it keeps). Then, for each, rank 0 broadcasts kSendBulk and the
// piece's index, and its owner sends the bulk ("" if it has none). The workers wait for commands
// then.
class RemoteBulks : public BulkStore {
 public:
  explicit RemoteBulks(RankStats& stats) : stats_(stats) {}
  void owned_by(int piece, int rank) { owners_[piece] = rank; }
  bool put(int, const TetBlock&) override { return false; }  // a bulk split again stays on rank 0
  void number(const std::vector<BulkShare>& shares) override {
    std::vector<BulkShare> kept;
    for (const BulkShare& share : shares)
      if (owners_.count(share.piece)) kept.push_back(share);
    if (kept.empty()) return;
    broadcast(kNumberBulks);
    broadcast_text(serialize_bulk_shares(kept));
  }
  TetBlock take(int piece) override {
    const auto owner = owners_.find(piece);
    if (owner == owners_.end()) throw InternalError("no rank keeps the bulk of piece " + std::to_string(piece));
    const int rank = owner->second;
    owners_.erase(owner);
    broadcast(kSendBulk);
    bounded([&] { return broadcast_int(piece, 0, job_comm(), collective_limit()); });
    AddSeconds timer{stats_.receive_seconds};
    std::string bytes;
    try {
      bytes = recv_bytes(rank, kTagBulk, job_comm(), kMaxChunk, kWorkerSeconds);
    } catch (const Stalled&) {
      abort_job("rank " + std::to_string(rank) + " did not send the mesh of piece " + std::to_string(piece) +
                " it kept within " + std::to_string(static_cast<int>(kWorkerSeconds)) + " s (stopped or dead?)");
    }
    stats_.bytes_received += static_cast<double>(bytes.size());
    if (bytes.empty())
      throw InternalError("rank " + std::to_string(rank) + " no longer keeps the mesh of piece " +
                          std::to_string(piece));
    return deserialize_block(bytes);
  }

 private:
  RankStats& stats_;
  std::map<int, int> owners_;  // piece -> the rank keeping its bulk
};

// Rank 0's side of the meshing, a dynamic master/worker queue: each piece goes to whichever
// rank is free as soon as it is closed; once all are closed, the rest go largest first. Rank 0
// meshes pieces too when the runner works in the background (a child process it polls between
// MPI messages), from the end of the closure on, so with -np 2 both cores work. Outcomes are
// stored by submission, so the result does not depend on which rank meshed what.
class RootScheduler : public PieceScheduler {
 public:
  RootScheduler(const MeshJob& job, int size, RankStats& stats, std::map<int, PieceRecord>& records, double job_start)
      : job_(job),
        runner_(job.options.tetgen, job.options.run),
        size_(size),
        stats_(stats),
        records_(records),
        job_start_(job_start),
        silence_limit_(silence_limit()),
        remote_(stats) {}

  // The other ranks are checking the input (check_input_on_rank); confirm_input waits for rank 1's verdict.
  void expect_input_verdict(std::size_t faces) {
    verdict_pending_ = true;
    // With other checking ranks, twice rank 1's own wait for them (input_verdict): when one of
    // them stalls, rank 1's verdict naming it comes first, not a timeout here naming rank 1.
    // On 2 ranks rank 1 waits for nobody, and neither need rank 0 wait longer.
    verdict_limit_ = (size_ > 2 ? 2 : 1) * input_check_limit(faces);
  }

  bool confirm_input() override {
    if (!verdict_pending_) return false;
    verdict_pending_ = false;
    std::string verdict;
    try {
      verdict = recv_bytes(1, kTagVerdict, job_comm(), kMaxChunk, verdict_limit_);
    } catch (const Stalled&) {
      abort_job("rank 1 has not reported its check of the input within " +
                std::to_string(static_cast<int>(verdict_limit_)) + " s (stopped or dead?)");
    }
    if (verdict.empty()) return true;
    if (verdict[0] == 'I') throw InputError(verdict.substr(1));
    // A checking rank failed or fell silent: the input is not known to be valid, and another
    // partition would not change that (nor wake a stopped rank).
    abort_job(verdict.substr(1));
  }

  BulkStore* split_where_meshed(const BandSpec& spec) override {
    if (size_ < 2) return nullptr;
    split_order_ = SplitOrder{spec, ++split_attempts_};
    return &remote_;
  }

  void begin_round(const TetgenOptions& tetgen) override {
    split_order_.reset();
    runner_ = PieceRunner(tetgen, job_.options.run);
    ++rounds_;
    done_ = 0;
    broadcast(kMeshPieces);
    pieces_.clear();
    position_.clear();
    queue_.clear();
    outcomes_.clear();
    arrived_.clear();
    cap_queue_.clear();
    caps_.clear();
    idle_.clear();
    for (int w = 1; w < size_; ++w) idle_.push_back(w);
    remaining_ = 0;
  }

  void submit(const PieceSurface& piece) override {
    position_[piece.index] = pieces_.size();
    pieces_.push_back(&piece);
    outcomes_.emplace_back();
    queue_.push_back(pieces_.size() - 1);
    ++remaining_;
    dispatch();
  }

  // Every cap goes to a queue in plane order. A free worker takes a piece when one is waiting and
  // else the next cap (which brings the next pieces closer), so no rank idles while either kind
  // of work is there; this rank builds the next queued cap itself while it waits for one that
  // another rank builds.
  void share_caps(std::vector<CapBorder> borders) override {
    cap_borders_ = std::move(borders);
    for (const CapBorder& border : cap_borders_)
      if (!border.chords.empty()) cap_queue_.push_back(border.plane);
    dispatch();
  }

  CapShape cap(int plane) override {
    const CapBorder& border = cap_borders_.at(static_cast<std::size_t>(plane));
    if (border.chords.empty()) return triangulate_cap(border);  // nothing to close on this plane
    std::chrono::microseconds idle = kShortestIdle;
    for (;;) {
      bool replied = false;
      while (receive_reply()) replied = true;
      // Returned before any dispatch: a rank freed just now takes the piece this cap completes,
      // not another cap.
      if (auto done = caps_.find(plane); done != caps_.end()) {
        CapOutcome outcome = std::move(done->second);
        caps_.erase(done);
        if (outcome.failure) throw PartitionError(*outcome.failure);
        return std::move(outcome.shape);
      }
      dispatch();
      // Not handed out yet: build it here. Being built elsewhere: build the next one meanwhile.
      auto queued = std::find(cap_queue_.begin(), cap_queue_.end(), plane);
      if (queued == cap_queue_.end()) queued = cap_queue_.begin();
      if (queued != cap_queue_.end()) {
        const int here = *queued;
        cap_queue_.erase(queued);
        build_cap_here(here);
        idle = kShortestIdle;
      } else {
        check_workers_answer();
        idle = replied ? kShortestIdle : sleep_idle(idle);
      }
    }
  }

  void progress() override {
    while (receive_reply()) {
    }
    check_workers_answer();
    if (own_ && own_->poll(0)) finish_own_piece();
    dispatch();
  }

  void end_round(const Arrived& arrived) override {
    cap_queue_.clear();  // after a closure that failed: the caps not handed out are not needed
    std::stable_sort(queue_.begin(), queue_.end(), [&](std::size_t a, std::size_t b) {
      return pieces_[a]->triangles.size() > pieces_[b]->triangles.size();
    });
    const bool root_meshes = runner_.runs_in_background() || size_ == 1;
    std::chrono::microseconds idle = kShortestIdle;
    while (remaining_ > 0 || caps_out() > 0) {
      dispatch();
      if (root_meshes && !own_ && !queue_.empty()) start_own_piece();
      deliver(arrived);  // once every free rank (this one too) has its next piece
      bool progress = receive_reply();
      if (own_ && own_->poll(0)) progress = finish_own_piece();
      check_workers_answer();
      if (progress)
        idle = kShortestIdle;
      else
        idle = sleep_idle(idle);
    }
    for (int w = 1; w < size_; ++w) send_piece(w, nullptr);  // round over
    take_alive();  // the last ones, sent before the replies, so none is left for later
    deliver(arrived);
  }

 private:
  // Sleeps in the kernel (on the child's pipe when there is one, which wakes it when the child
  // is done) between looks at MPI; returns the next pause.
  std::chrono::microseconds sleep_idle(std::chrono::microseconds pause) {
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(pause);
    if (own_ && ms.count() > 0)
      own_->poll(static_cast<int>(ms.count()));
    else
      std::this_thread::sleep_for(pause);
    return std::min(pause * 2, kLongestIdle);
  }

  void dispatch() {
    while (!idle_.empty() && (!cap_queue_.empty() || !queue_.empty())) {
      const int worker = idle_.back();
      idle_.pop_back();
      if (!queue_.empty()) {
        send_piece(worker, pieces_[take_next()]);
      } else {
        const int plane = cap_queue_.front();
        cap_queue_.pop_front();
        send_cap(worker, plane);
      }
    }
  }

  void build_cap_here(int plane) {
    caps_[plane] = triangulated(cap_borders_.at(static_cast<std::size_t>(plane)), stats_);
  }

  // Caps other ranks are building.
  std::size_t caps_out() const {
    return static_cast<std::size_t>(
        std::count_if(busy_.begin(), busy_.end(), [](const auto& worker) { return worker.second.cap; }));
  }

  // A cap takes far less than a piece: a rank that has not answered within a piece's wall time
  // limit (when one is set) or kWorkerSeconds is stopped or dead.
  double cap_limit() const {
    const double piece_limit = job_.options.run.timeout_seconds;
    return piece_limit > 0 ? std::min(kWorkerSeconds, kWallPerCpuSecond * piece_limit + kReplyGraceSeconds)
                           : kWorkerSeconds;
  }

  void send_cap(int worker, int plane) {
    AddSeconds timer{stats_.send_seconds};
    const std::string bytes = serialize_cap_task(cap_borders_.at(static_cast<std::size_t>(plane)));
    busy_[worker] = {awake_seconds() + cap_limit(), plane, true, ++tasks_[worker]};
    try {
      stats_.bytes_sent +=
          static_cast<double>(send_bytes(bytes, worker, kTagPiece, job_comm(), kMaxChunk, cap_limit()));
    } catch (const Stalled&) {
      abort_job("rank " + std::to_string(worker) + " did not take the cap of plane " + std::to_string(plane) +
                " within " + std::to_string(static_cast<int>(cap_limit())) + " s (stopped or dead?)");
    }
  }

  // Hands the outcomes stored since the last call to the pipeline. Each is moved out first, so
  // a callback that submits more work (which grows outcomes_ and arrived_) holds no reference
  // into them.
  void deliver(const Arrived& arrived) {
    std::vector<std::size_t> positions;
    positions.swap(arrived_);
    for (std::size_t position : positions) {
      PieceOutcome outcome = std::move(outcomes_[position]);
      arrived(position, std::move(outcome));
    }
  }

  std::size_t take_next() {
    const std::size_t next = queue_.front();
    queue_.erase(queue_.begin());
    return next;
  }

  // Sends a piece to a worker, or an empty message: round over.
  void send_piece(int worker, const PieceSurface* piece) {
    AddSeconds timer{stats_.send_seconds};
    std::string bytes;
    if (piece) {
      record(*piece, worker);
      bytes = serialize_task(*piece, runner_.tetgen(), piece->seam_region || !split_order_ ? nullptr : &*split_order_);
      busy_[worker] = {awake_seconds() + runner_.wall_limit(*piece) + kReplyGraceSeconds, piece->index, false,
                       ++tasks_[worker]};
      account_meshing();
    }
    // A piece larger than MPI's eager limit waits for the worker to take it: a worker stopped
    // while idle is noticed here, within the same limit as one stopped while meshing.
    const double limit =
        piece ? std::min(kWorkerSeconds, runner_.wall_limit(*piece) + kReplyGraceSeconds) : kWorkerSeconds;
    try {
      stats_.bytes_sent += static_cast<double>(send_bytes(bytes, worker, kTagPiece, job_comm(), kMaxChunk, limit));
    } catch (const Stalled&) {
      abort_job(piece ? "rank " + std::to_string(worker) + " has not answered for piece " +
                            std::to_string(piece->index) + " within its time limit (stopped or dead?)"
                      : "rank " + std::to_string(worker) + " did not take a message within " +
                            std::to_string(static_cast<int>(limit)) + " s (stopped or dead?)");
    }
  }

  // A worker that does not answer within its piece's wall time limit (its TetGen child would
  // have been stopped by then), or falls silent while its TetGen process is at work, is
  // stopped, hung or dead.
  void check_workers_answer() {
    take_alive();
    const double now = awake_seconds();
    for (const auto& [worker, busy] : busy_) {
      if (busy.meshing && now - busy.heard > silence_limit_)
        abort_job("rank " + std::to_string(worker) + " has not been heard from for " +
                  std::to_string(static_cast<int>(silence_limit_)) + " s while meshing piece " +
                  std::to_string(busy.piece) + " (stopped, hung, or its node lost?)");
      if (now > busy.deadline)
        abort_job("rank " + std::to_string(worker) + " has not answered for " +
                  (busy.cap ? "the cap of plane " : "piece ") + std::to_string(busy.piece) +
                  " within its time limit (stopped or dead?)");
    }
  }

  // The workers' heartbeats that have come: each says whether its TetGen process is at work on
  // its latest task (one for a task already answered is late, and changes nothing).
  void take_alive() {
    for (const auto& [worker, alive] : take_heartbeats(job_comm())) {
      const auto busy = busy_.find(worker);
      if (busy == busy_.end() || busy->second.task != alive.task) continue;
      busy->second.meshing = alive.meshing != 0;
      busy->second.heard = awake_seconds();
    }
  }

  void start_own_piece() {
    own_position_ = take_next();
    const PieceSurface& piece = *pieces_[own_position_];
    record(piece, 0);
    own_start_ = now_seconds();
    if (!piece.seam_region) dump_piece(job_, piece);
    own_ = runner_.start(piece, [&piece] {
      if (!piece.seam_region) test_hooks::piece_failure(piece.index, 0);
    });
    account_meshing();
  }

  bool finish_own_piece() {
    store(own_position_, deserialize_outcome(own_->take_reply()));
    stats_.pieces_from_checkpoint += own_->from_checkpoint();
    own_.reset();
    account_meshing();
    (pieces_[own_position_]->seam_region ? stats_.region_seconds : stats_.tetgen_seconds) += now_seconds() - own_start_;
    if (!pieces_[own_position_]->seam_region) stats_.pieces += 1;
    report_progress(own_position_, 0);
    return true;
  }

  // One line per finished piece or seam region: "pieces 5/16 done, 41.2 s, rank 1 idle". The
  // total is the pieces asked for in the first round (they are still being closed), the pieces
  // submitted in later ones (retries re-mesh only the pieces that changed).
  void report_progress(std::size_t position, int rank) {
    ++done_;
    const bool seams = pieces_[position]->seam_region;
    std::size_t total = pieces_.size();
    if (!seams && rounds_ == 1) total = std::max(total, static_cast<std::size_t>(job_.options.pieces));
    std::string line = std::string(seams ? "seam regions " : "pieces ") + std::to_string(done_) + "/" +
                       std::to_string(total) + " done, " + std::to_string(now_seconds() - job_start_);
    line.erase(line.find('.') + 2);  // one decimal
    line += " s (" + std::string(seams ? "region " : "piece ") + std::to_string(pieces_[position]->index) +
            " on rank " + std::to_string(rank) + ")";
    if (queue_.empty() && done_ < total) {
      std::vector<int> idle = idle_;
      if (!own_ && (runner_.runs_in_background() || size_ == 1)) idle.push_back(0);
      std::sort(idle.begin(), idle.end());
      for (std::size_t i = 0; i < idle.size(); ++i)
        line += (i == 0 ? (idle.size() == 1 ? ", rank " : ", ranks ") : ", ") + std::to_string(idle[i]);
      if (!idle.empty()) line += " idle";
    }
    log::info(line);
  }

  // Takes a worker's reply if one has arrived; the worker is free again.
  bool receive_reply() {
    int arrived = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, kTagReply, job_comm(), &arrived, &status);
    if (!arrived) return false;
    const int worker = status.MPI_SOURCE;
    std::size_t position = 0;
    {
      AddSeconds timer{stats_.receive_seconds};
      const std::string reply = recv_bytes(worker, kTagReply, job_comm());
      stats_.bytes_received += static_cast<double>(reply.size());
      if (is_cap_outcome(reply)) {
        CapOutcome outcome = deserialize_cap_outcome(reply);
        const int plane = busy_.at(worker).piece;
        if (!outcome.failure && outcome.shape.plane != plane)
          throw InternalError("rank " + std::to_string(worker) + " sent the cap of another plane");
        caps_[plane] = std::move(outcome);
        idle_.push_back(worker);
        busy_.erase(worker);
        return true;
      }
      PieceOutcome outcome = deserialize_outcome(reply);
      const int index = outcome.failure ? outcome.failure->piece
                        : outcome.band  ? outcome.band->index
                                        : outcome.result.index;
      position = position_.at(index);
      if (outcome.band) remote_.owned_by(index, worker);
      store(position, std::move(outcome));
    }
    idle_.push_back(worker);
    busy_.erase(worker);
    account_meshing();
    report_progress(position, worker);
    return true;
  }

  // Adds the time since the last change to the meshing wall time if some rank was meshing.
  void account_meshing() {
    const double now = now_seconds();
    if (meshing_ > 0) stats_.meshing_wall_seconds += now - meshing_since_;
    meshing_since_ = now;
    meshing_ = busy_.size() + (own_ ? 1 : 0);
  }

  // Where each piece (not seam region) was meshed, for the report.
  void record(const PieceSurface& piece, int rank) {
    if (!piece.seam_region)
      records_[piece.index] = {piece.index, rank, static_cast<std::int64_t>(piece.triangles.size()), 0, 0, 0};
  }

  void store(std::size_t position, PieceOutcome&& outcome) {
    if (!pieces_[position]->seam_region) {
      records_[pieces_[position]->index].seconds = outcome.seconds;
      records_[pieces_[position]->index].memory_mb = outcome.memory_mb;
      records_[pieces_[position]->index].tets =
          outcome.band ? static_cast<std::int64_t>(outcome.band->band.tets.size()) + outcome.band->bulk_tets
                       : static_cast<std::int64_t>(outcome.result.mesh.tets.size());
    }
    outcomes_[position] = std::move(outcome);
    arrived_.push_back(position);
    --remaining_;
  }

  const MeshJob& job_;
  PieceRunner runner_;  // this round's TetGen options
  int size_;
  RankStats& stats_;
  std::map<int, PieceRecord>& records_;      // by piece index: the latest meshing of each piece
  std::vector<const PieceSurface*> pieces_;  // submitted this round
  std::map<int, std::size_t> position_;      // piece index -> position in pieces_
  std::vector<std::size_t> queue_;           // positions not handed out yet
  std::vector<PieceOutcome> outcomes_;       // by position, until delivered
  std::vector<std::size_t> arrived_;         // positions stored but not delivered yet
  std::vector<int> idle_;                    // workers without a piece
  struct Busy {
    double deadline;  // when its answer is overdue (awake_seconds: a suspended job's pause does not count)
    int piece;        // or plane, for a cap
    bool cap;
    std::uint64_t task;    // the worker's task number (its heartbeats name it)
    double heard = 0;      // its latest heartbeat (awake_seconds)
    bool meshing = false;  // its TetGen process is at work: its heartbeats must not stop
  };
  std::map<int, Busy> busy_;            // workers with a piece
  std::map<int, std::uint64_t> tasks_;  // per worker: the tasks sent (pieces, regions, caps)
  std::size_t remaining_ = 0;
  std::deque<int> cap_queue_;       // planes whose caps nobody builds yet
  std::map<int, CapOutcome> caps_;  // by plane: built, not yet taken by cap()
  std::unique_ptr<PieceJob> own_;
  std::size_t own_position_ = 0;
  double own_start_ = 0;
  bool verdict_pending_ = false;  // rank 1's check of the input not heard yet
  double verdict_limit_ = 0;
  std::size_t meshing_ = 0;                // pieces or regions being meshed now, on all ranks
  double meshing_since_ = 0;               // when that count last changed
  double job_start_;                       // for the progress lines
  double silence_limit_;                   // silence_limit()
  int rounds_ = 0;                         // rounds begun
  std::size_t done_ = 0;                   // pieces or regions finished this round
  RemoteBulks remote_;                     // the bulks the workers keep
  std::optional<SplitOrder> split_order_;  // this round's pieces are split where meshed
  std::int32_t split_attempts_ = 0;
};

// A worker's part of the closure: triangulates the cap and sends rank 0 its shape, or the failure.
void build_cap_for_root(const std::string& task, int rank, RankStats& stats) {
  test_hooks::cap_stop(rank);
  const CapBorder border = deserialize_cap_task(task);
  const CapOutcome outcome = triangulated(border, stats, [&border] { test_hooks::worker_cap_failure(border.plane); });
  const std::string reply = serialize_cap_outcome(outcome);
  AddSeconds timer{stats.send_seconds};
  stats.bytes_sent += static_cast<double>(
      bounded([&] { return send_bytes(reply, 0, kTagReply, job_comm(), kMaxChunk, kRootSeconds); }));
}

// The bulks a worker keeps: of the pieces it meshed and split in rank 0's latest attempt; with
// --scratch in one nameless file in that directory on this rank's node (in memory where it cannot
// write).
class KeptBulks {
 public:
  KeptBulks(const std::string& scratch, RankStats& stats) : scratch_(scratch), stats_(stats) { new_attempt(-1); }
  std::int32_t attempt() const { return attempt_; }
  // Drops the bulks of earlier attempts (and their files).
  void new_attempt(std::int32_t attempt) {
    attempt_ = attempt;
    bulks_.clear();
    shares_.clear();
    on_disk_.reset();
    if (!scratch_.empty()) on_disk_ = std::make_unique<ScratchBulks>(scratch_);
  }
  void keep(int piece, TetBlock&& bulk) {
    stats_.bulks_kept += 1;
    if (on_disk_ && on_disk_->put(piece, bulk)) {
      stats_.bulks_on_disk += 1;
      bulks_.erase(piece);
      return;
    }
    bulks_[piece] = std::move(bulk);
  }
  void forget(int piece) {
    bulks_.erase(piece);
    shares_.erase(piece);
    if (on_disk_) on_disk_->drop(piece);
  }
  // Numbers the bulks kept in memory at once and those on disk as they are taken. A bulk that does
  // not fit its share is forgotten (rank 0 then learns this rank no longer keeps it).
  void number(std::vector<BulkShare> shares) {
    for (BulkShare& share : shares) {
      const int piece = share.piece;
      if (auto it = bulks_.find(piece); it != bulks_.end()) {
        try {
          number_bulk(it->second, share.numbering, share.first_steiner);
        } catch (const std::exception& e) {
          log::error("piece " + std::to_string(piece) + ": " + e.what());
          forget(piece);
        }
      } else if (on_disk_ && on_disk_->holds(piece)) {
        shares_[piece] = std::move(share);
      }
    }
  }
  // Piece's bulk, once; nothing when this rank does not keep it.
  std::optional<TetBlock> take(int piece) {
    if (auto it = bulks_.find(piece); it != bulks_.end()) {
      TetBlock bulk = std::move(it->second);
      bulks_.erase(it);
      return bulk;
    }
    if (on_disk_ && on_disk_->holds(piece)) {
      TetBlock bulk = on_disk_->take(piece);
      if (auto share = shares_.find(piece); share != shares_.end()) {
        number_bulk(bulk, share->second.numbering, share->second.first_steiner);
        shares_.erase(share);
      }
      return bulk;
    }
    return std::nullopt;
  }

 private:
  std::string scratch_;
  RankStats& stats_;
  std::int32_t attempt_ = -1;
  std::map<int, TetBlock> bulks_;  // by piece, in memory
  std::unique_ptr<ScratchBulks> on_disk_;
  std::map<int, BulkShare> shares_;  // by piece: the numbering of a bulk on disk, for its take
};

std::string out_of_memory_message(int rank);

// A worker's reply for a piece to split where it was meshed: its band (the bulk kept), or the
// reply as it came when meshing failed. A split that fails is the piece's failure.
std::string split_here(std::string reply, const PieceSurface& piece, const SplitOrder& order, KeptBulks& kept) {
  PieceOutcome outcome;
  try {
    outcome = deserialize_outcome(reply);
  } catch (const std::exception&) {
    return reply;  // rank 0 reports it, as any reply it cannot read
  }
  if (outcome.failure) return reply;
  std::string().swap(reply);
  try {
    PieceBand band = split_where_meshed(std::move(outcome.result), piece.global_ids, order.spec);
    log::debug("piece " + std::to_string(piece.index) + ": " + std::to_string(band.band.tets.size()) +
               " band tets to rank 0, " + std::to_string(band.bulk_tets) + " bulk tets kept here");
    kept.keep(piece.index, std::move(band.bulk));
    outcome.band = std::move(band);
    return serialize_outcome(outcome);
  } catch (const std::bad_alloc&) {
    outcome.failure = Failure(FailureKind::other, piece.index, {}, out_of_memory_message(my_rank()));
  } catch (const std::exception& e) {
    outcome.failure = Failure(FailureKind::other, piece.index, {}, e.what());
  }
  kept.forget(piece.index);
  outcome.band.reset();
  return serialize_outcome(outcome);
}

// A worker's side of kSendBulk: the owner of the piece sends its bulk and forgets it.
void send_kept_bulk(KeptBulks& kept, RankStats& stats) {
  const int piece = bounded([] { return broadcast_int(0, 0, job_comm(), kRootSeconds); });
  std::string bytes;
  try {
    std::optional<TetBlock> bulk = kept.take(piece);
    if (!bulk) return;  // another rank's
    bytes = serialize_block(*bulk);
  } catch (const std::exception& e) {  // not read back from scratch: rank 0 gets an empty answer and says so
    log::error(e.what());
    bytes.clear();
  }
  AddSeconds timer{stats.send_seconds};
  stats.bytes_sent +=
      static_cast<double>(bounded([&] { return send_bytes(bytes, 0, kTagBulk, job_comm(), kMaxChunk, kRootSeconds); }));
}

// A worker's side of kNumberBulks: it numbers the bulks it keeps with their shares. Shares it
// cannot read leave its bulks as they are; rank 0 then numbers them itself.
void number_kept_bulks(KeptBulks& kept, RankStats& stats) {
  const std::string bytes = broadcast_text("");
  AddSeconds timer{stats.bulk_number_seconds};
  try {
    kept.number(deserialize_bulk_shares(bytes));
  } catch (const std::exception& e) {
    log::error(std::string("the numbering of the kept bulks: ") + e.what());
  }
}

// Waits for a piece's reply, telling rank 0 meanwhile that this rank is alive (heartbeat.hpp).
std::string reply_with_heartbeats(PieceJob& job, std::uint64_t task, int rank) {
  Heartbeat heartbeat(job_comm(), task);
  do {
    heartbeat.meshing();
    test_hooks::meshing_stop(rank);
  } while (!job.poll(250));
  heartbeat.done();
  return job.take_reply();
}

// A worker: in each round, mesh the pieces and build the caps rank 0 hands out until it sends an
// empty message; between rounds, send the bulks it kept when rank 0 asks for them.
void worker_loop(const MeshJob& job, int rank, RankStats& stats) {
  if (!job.options.scratch.empty()) remove_stale_scratch(job.options.scratch);  // this node's dead runs'
  KeptBulks kept(job.options.scratch, stats);
  std::uint64_t tasks = 0;  // taken: pieces, regions and caps, as rank 0 counts them
  for (Command command = receive_command(); command != kDone; command = receive_command()) {
    if (command == kSendBulk) {
      send_kept_bulk(kept, stats);
      continue;
    }
    if (command == kNumberBulks) {
      number_kept_bulks(kept, stats);
      continue;
    }
    for (;;) {
      std::string bytes;
      {
        AddSeconds timer{stats.receive_seconds};
        bytes = bounded([] { return recv_bytes(0, kTagPiece, job_comm(), kMaxChunk, kRootSeconds); });
      }
      stats.bytes_received += static_cast<double>(bytes.size());
      if (bytes.empty()) break;
      ++tasks;
      if (task_kind(bytes) == TaskKind::cap) {
        build_cap_for_root(bytes, rank, stats);
        continue;
      }
      TetgenOptions tetgen;
      std::optional<SplitOrder> split;
      const PieceSurface piece = deserialize_task(bytes, tetgen, &split);
      if (split && split->attempt != kept.attempt()) kept.new_attempt(split->attempt);
      const PieceRunner runner(tetgen, job.options.run);
      const bool region = piece.seam_region;
      std::string().swap(bytes);
      if (!region) dump_piece(job, piece);
      std::string reply;
      {
        AddSeconds timer{region ? stats.region_seconds : stats.tetgen_seconds};
        const std::unique_ptr<PieceJob> job = runner.start(piece, [&piece, rank, region] {
          if (!region) test_hooks::piece_failure(piece.index, rank);
        });
        reply = reply_with_heartbeats(*job, tasks, rank);
        stats.pieces_from_checkpoint += job->from_checkpoint();
        if (split) reply = split_here(std::move(reply), piece, *split, kept);
      }
      if (!region) stats.pieces += 1;
      AddSeconds timer{stats.send_seconds};
      stats.bytes_sent += static_cast<double>(
          bounded([&] { return send_bytes(reply, 0, kTagReply, job_comm(), kMaxChunk, kRootSeconds); }));
      test_hooks::worker_stop(rank);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// 9. Writing with every rank. Rank 0 broadcasts an order ("hdf5" or "rows", then its details on
// further lines), and sends each rank its block; an empty order ends the writes. (Until the
// pieces' tets stay with the ranks that meshed them, rank 0 deals the blocks out.)
// - hdf5: the HDF5 files of an XDMF set, written by every rank at once (parallel HDF5).
// - rows: the lines of a TetGen file; each rank formats its block of rows while rank 0 formats
//   its own, then sends the text back in chunks ("T" + text; "E" + a message when it cannot;
//   then an empty chunk), which rank 0 writes in order after its own block. The block comes in
//   parts of kRowPart rows, so a rank frees each part as it formats it: it holds its text and
//   one part, not its whole block beside its text.
// - pieces: the files of a set with one file per piece (a .pvtu set's, the MSH partitions); each
//   rank that sees the output directory writes some, each file going to whichever rank is free
//   (see PieceFileDealer).

constexpr int kTagText = 6;
// Bytes of text per message: rank 0 holds one such chunk at a time beside the mesh.
constexpr std::size_t kTextChunk = std::size_t{8} << 20;
// Rows per part of a block (32 MB of .node rows, 16 MB of .ele rows).
constexpr std::size_t kRowPart = std::size_t{1} << 20;

// How many parts the block of rows [first, last) travels in: kRowPart rows each, the last
// shorter; an empty block is one empty part. Sender and receiver both count by this.
std::size_t row_part_count(std::size_t first, std::size_t last) {
  return std::max<std::size_t>(1, (last - first + kRowPart - 1) / kRowPart);
}

// An absolute path, or an OutputError when the working directory cannot be named.
std::string absolute_or_error(const std::string& path) {
  std::string absolute = absolute_path(path);
  if (absolute.empty() || absolute[0] != '/') throw OutputError("cannot find the working directory");
  return absolute;
}

// A block of the HDF5 files goes to its rank as a header ("B", or "" when rank 0 cannot make it),
// then its six arrays' bytes, straight from the mesh (mesh_block_view): no copy of it on either
// side.
constexpr int kBlockArrays = 6;

void send_block(const MeshBlockView& block, bool ok, int rank) {
  const auto send = [rank](const auto& run) {
    const std::string_view bytes(reinterpret_cast<const char*>(run.data), run.size * sizeof(*run.data));
    bounded([&] { return send_bytes(bytes, rank, kTagBlock, job_comm(), kMaxChunk, kWorkerSeconds); });
  };
  bounded([&] { return send_bytes(ok ? "B" : "", rank, kTagBlock, job_comm(), kMaxChunk, kWorkerSeconds); });
  if (!ok) return;
  send(block.points), send(block.tets), send(block.tet_region), send(block.tet_piece);
  send(block.faces), send(block.face_marker);
}

// A worker's block as it came: the six arrays' bytes, viewed in place.
struct ReceivedBlock {
  bool made = false;  // rank 0 could make it
  std::string arrays[kBlockArrays];

  static ReceivedBlock receive() {
    ReceivedBlock block;
    const auto receive_one = [] {
      return bounded([&] { return recv_bytes(0, kTagBlock, job_comm(), kMaxChunk, kRootSeconds); });
    };
    block.made = !receive_one().empty();
    if (block.made)
      for (std::string& bytes : block.arrays) bytes = receive_one();
    return block;
  }

  // The view, or nothing when the arrays do not fit together (lost or cut bytes).
  std::optional<MeshBlockView> view() const {
    if (!made) return std::nullopt;
    MeshBlockView block;
    const bool whole = as_runs(std::vector<std::string_view>(std::begin(arrays), std::end(arrays)), block.points,
                               block.tets, block.tet_region, block.tet_piece, block.faces, block.face_marker);
    if (!whole || block.tet_region.size != block.tets.size || block.tet_piece.size != block.tets.size ||
        block.face_marker.size != block.faces.size)
      return std::nullopt;
    return block;
  }
};

// Rank 0's Hdf5Write. A block it cannot make goes as a header alone, so every rank still joins
// the collective write and learns of the failure there.
MeshTotals write_hdf5_on_every_rank(const MeshOutput& output, const Hdf5Paths& relative) {
  // Absolute paths: the ranks' working directories may differ.
  Hdf5Paths paths = relative;
  paths.mesh = absolute_or_error(relative.mesh), paths.boundary = absolute_or_error(relative.boundary);
  broadcast_text("hdf5\n" + paths.mesh + '\n' + paths.boundary + '\n' + paths.mesh_shown + '\n' + paths.boundary_shown);
  int size = 1;
  MPI_Comm_size(job_comm(), &size);
  std::vector<std::int32_t> region;
  bool ok = true;
  try {
    region = region_of_tets(output.mesh);
  } catch (const std::bad_alloc&) {
    ok = false;
  }
  MadeColumns made;
  for (int r = 1; r < size; ++r) {
    MeshBlockView block;
    if (ok) try {
        block = mesh_block_view(output, region, r, size, made);
      } catch (const std::bad_alloc&) {
        ok = false;
      }
    send_block(block, ok, r);
  }
  MeshBlockView own;
  if (ok) own = mesh_block_view(output, region, 0, size, made);
  return write_mesh_hdf5(job_comm(), own, paths, ok ? WriteTrouble::none : WriteTrouble::no_block);
}

// Rank 0's TetgenLines. It goes on taking every rank's chunks after a failure of its own (a full
// disk), so no rank is left waiting, then throws the first failure.
void write_tetgen_lines_on_every_rank(const TetgenRows& rows, BufferedFile& out) {
  int size = 1;
  MPI_Comm_size(job_comm(), &size);
  broadcast_text("rows\n" + std::to_string(static_cast<int>(rows.file)) + '\n' + std::to_string(rows.count) + '\n' +
                 std::to_string(rows.split_from));
  const std::size_t bytes_per_row = row_bytes(rows.file);
  for (int r = 1; r < size; ++r) {
    const auto [first, last] = run_of(rows.count, r, size);
    for (std::size_t i = 0; i < row_part_count(first, last); ++i) {
      const std::size_t row = first + i * kRowPart;
      const std::string_view part(rows.data + row * bytes_per_row,
                                  (std::min(last, row + kRowPart) - row) * bytes_per_row);
      bounded([&] { return send_bytes(part, r, kTagBlock, job_comm(), kMaxChunk, kWorkerSeconds); });
    }
  }
  std::exception_ptr failure;
  try {
    const auto [first, last] = run_of(rows.count, 0, size);
    write_tetgen_lines(rows, first, last - first, out);
  } catch (...) {
    failure = std::current_exception();
  }
  for (int r = 1; r < size; ++r)
    for (;;) {
      const std::string chunk = bounded([&] { return recv_bytes(r, kTagText, job_comm(), kMaxChunk, kWorkerSeconds); });
      if (chunk.empty()) break;
      if (failure) continue;
      if (chunk[0] == 'E') {
        failure = std::make_exception_ptr(OutputError(chunk.substr(1)));
        continue;
      }
      try {
        out.bytes(chunk.data() + 1, chunk.size() - 1);
      } catch (...) {
        failure = std::current_exception();
      }
    }
  if (failure) std::rethrow_exception(failure);
}

// A worker's side of a rows order: formats its block and sends the text back in chunks.
void format_rows_block(std::istringstream& order) {
  int file = 0;
  std::size_t count = 0, split_from = 0;
  order >> file >> count >> split_from;
  int size = 1;
  MPI_Comm_size(job_comm(), &size);
  const auto [first, last] = run_of(count, my_rank(), size);
  std::vector<std::string> parts(row_part_count(first, last));
  for (std::string& part : parts)
    part = bounded([&] { return recv_bytes(0, kTagBlock, job_comm(), kMaxChunk, kRootSeconds); });
  const auto kind = static_cast<TetgenFile>(file);
  const std::size_t bytes_per_row = row_bytes(kind);
  auto send = [](const std::string& chunk) {
    bounded([&] { return send_bytes(chunk, 0, kTagText, job_comm(), kMaxChunk, kRootSeconds); });
  };
  try {
    std::size_t received = 0;
    for (const std::string& part : parts) received += part.size();
    if (received != (last - first) * bytes_per_row || test_hooks::block_lost(my_rank()))
      throw OutputError("rank " + std::to_string(my_rank()) + " did not receive its block of the " +
                        std::string(extension(kind)) + " file's rows");
    // The whole block first (rank 0 is formatting its own meanwhile), then the chunks. Each
    // part's text is a string of its own: one string for the block would be copied as it grows.
    std::vector<std::string> texts(parts.size());
    for (std::size_t i = 0, row = first; i < parts.size(); ++i) {
      const std::size_t rows_in_part = parts[i].size() / bytes_per_row;
      append_tetgen_lines(texts[i], kind, parts[i].data(), row, rows_in_part, split_from);
      row += rows_in_part;
      std::string().swap(parts[i]);
    }
    std::string chunk;
    for (std::string& text : texts) {
      for (std::size_t done = 0; done < text.size(); done += kTextChunk) {
        chunk.assign("T");
        chunk.append(text, done, kTextChunk);
        send(chunk);
      }
      std::string().swap(text);
    }
  } catch (const std::exception& e) {
    send(std::string("E") + e.what());
  }
  send("");
}

// The files of a set with one file per piece (a .pvtu set's, the MSH partitions), written by
// every rank that sees the output directory, each file by whichever is free: every such rank is sent a file at once,
// then another each time it answers for the last, while rank 0 writes one itself between looks (so rank 0 never waits
// for a rank, and a faster node writes more). Rank 0 has made every file's temporary, so a rank that can open one
// shares rank 0's directory (the names hold rank 0's host and process id); a rank that cannot (a directory local to
// rank 0's node) is sent none. The exchange:
//   order (broadcast): "pieces\n", the format's name and '\n', then per file its temporary and
//                      final name, each ended by '\0';
//   rank -> 0: "1" or "0": whether it can open the first file's temporary;
//   0 -> rank: "B" + the file's index + "/" + the number of arrays, then the arrays of the
//              file's PieceArrays ("N" + index alone when rank 0 could not make them); "" when
//              there are no more;
//   rank -> 0: per file, "" once written, or "E" + why not.
constexpr char kPiecesOrder[] = "pieces";

std::string piece_files_order(MeshFormat format, const std::vector<PieceFile>& files) {
  std::string order = std::string(kPiecesOrder) + '\n' + mesh_format_name(format) + '\n';
  for (const PieceFile& file : files) order += absolute_or_error(file.temporary) + '\0' + file.shown + '\0';
  return order;
}

// Rank 0's PieceFilesWrite. After a failure it deals no more files, takes the answers still due,
// then throws the first failure.
class PieceFileDealer {
 public:
  PieceFileDealer(MeshFormat format, const std::vector<PieceFile>& files, const PieceArraysOf& arrays_of,
                  RankStats& stats)
      : format_(format), files_(files), arrays_of_(arrays_of), stats_(stats) {
    MPI_Comm_size(job_comm(), &size_);
    busy_.assign(static_cast<std::size_t>(size_), false);
  }

  void run() {
    broadcast_text(piece_files_order(format_, files_));
    find_writers();
    for (int rank : writers_) send_next(rank);
    while (next_ < files_.size()) {
      for (int rank : writers_)
        if (busy_[rank] && answered(rank)) take_answer(rank), send_next(rank);
      if (next_ < files_.size()) write_own(next_++);
    }
    for (int rank : writers_)
      if (busy_[rank]) take_answer(rank);
    for (int rank = 1; rank < size_; ++rank) send_to(rank, "");  // no more files
    if (failure_) std::rethrow_exception(failure_);
  }

 private:
  void find_writers() {
    for (int rank = 1; rank < size_; ++rank)
      if (bounded([&] { return recv_bytes(rank, kTagText, job_comm(), kMaxChunk, kWorkerSeconds); }) == "1")
        writers_.push_back(rank);
  }

  static void send_to(int rank, std::string_view bytes) {
    bounded([&] { return send_bytes(bytes, rank, kTagBlock, job_comm(), kMaxChunk, kWorkerSeconds); });
  }

  void send_next(int rank) {
    if (next_ >= files_.size() || failure_) return;
    const std::size_t i = next_++;
    std::optional<PieceArrays> arrays;
    try {
      arrays = arrays_of_(files_[i].piece);
    } catch (const std::bad_alloc&) {
      failure_ = std::make_exception_ptr(OutputError("rank 0 ran out of memory making '" + files_[i].shown + "'"));
    } catch (...) {
      failure_ = std::current_exception();  // the rank is still told, so it does not wait for the file
    }
    send_to(rank, arrays ? "B" + std::to_string(i) + "/" + std::to_string(arrays->size()) : "N" + std::to_string(i));
    if (arrays)
      for (std::string_view bytes : *arrays) send_to(rank, bytes);
    busy_[rank] = true;
  }

  static bool answered(int rank) {
    int arrived = 0;
    MPI_Iprobe(rank, kTagText, job_comm(), &arrived, MPI_STATUS_IGNORE);
    return arrived != 0;
  }

  void take_answer(int rank) {
    const std::string answer =
        bounded([&] { return recv_bytes(rank, kTagText, job_comm(), kMaxChunk, kWorkerSeconds); });
    busy_[rank] = false;
    if (!answer.empty() && !failure_) failure_ = std::make_exception_ptr(OutputError(answer.substr(1)));
  }

  void write_own(std::size_t i) {
    if (failure_) return;
    try {
      write_piece_file(format_, arrays_of_(files_[i].piece), files_[i].temporary, files_[i].shown);
      ++stats_.piece_files_written;
    } catch (...) {
      failure_ = std::current_exception();
    }
  }

  MeshFormat format_;
  const std::vector<PieceFile>& files_;
  const PieceArraysOf& arrays_of_;
  RankStats& stats_;
  int size_ = 1;
  std::vector<int> writers_;  // the other ranks that see the output directory
  std::vector<bool> busy_;    // per rank: it was sent a file it has not answered for
  std::size_t next_ = 0;      // the first file not yet dealt
  std::exception_ptr failure_;
};

// A piece file's arrays as they came ("B" + index + "/" + count: that many arrays follow).
std::vector<std::string> receive_piece_arrays(const std::string& header) {
  std::vector<std::string> arrays;
  if (header[0] != 'B' || header.find('/') == std::string::npos) return arrays;
  arrays.resize(std::stoul(header.substr(header.find('/') + 1)));
  for (std::string& bytes : arrays)
    bytes = bounded([&] { return recv_bytes(0, kTagBlock, job_comm(), kMaxChunk, kRootSeconds); });
  return arrays;
}

// A worker's side of a pieces order: says whether it sees the output directory, then writes each
// file it is sent and answers for it, until rank 0 says there are no more.
void write_piece_files_sent(std::istringstream& order, RankStats& stats) {
  std::string format_name;
  std::getline(order, format_name);
  const MeshFormat format = mesh_format(format_name);
  std::vector<PieceFile> files;
  std::string temporary, shown;
  while (std::getline(order, temporary, '\0') && std::getline(order, shown, '\0'))
    files.push_back({0, temporary, shown});
  const int fd = files.empty() ? -1 : ::open(files[0].temporary.c_str(), O_WRONLY | O_CLOEXEC);  // never creates it
  if (fd >= 0) ::close(fd);
  bounded([&] { return send_bytes(fd >= 0 ? "1" : "0", 0, kTagText, job_comm(), kMaxChunk, kRootSeconds); });
  for (;;) {
    const std::string header = bounded([&] { return recv_bytes(0, kTagBlock, job_comm(), kMaxChunk, kRootSeconds); });
    if (header.empty()) return;
    const std::size_t i = std::stoul(header.substr(1));
    std::string answer;
    try {
      std::vector<std::string> received = receive_piece_arrays(header);
      if (test_hooks::block_lost(my_rank())) received.clear();
      if (i >= files.size() || received.empty())
        throw OutputError("rank " + std::to_string(my_rank()) + " did not receive the content of '" +
                          (i < files.size() ? files[i].shown : header) + "'");
      write_piece_file(format, PieceArrays(received.begin(), received.end()), files[i].temporary, files[i].shown);
      ++stats.piece_files_written;
    } catch (const std::exception& e) {
      answer = std::string("E") + e.what();
    }
    bounded([&] { return send_bytes(answer, 0, kTagText, job_comm(), kMaxChunk, kRootSeconds); });
  }
}

void end_writes() { broadcast_text(""); }

// A worker's side of the HDF5 files of an XDMF set.
void join_hdf5_write(std::istringstream& lines, JobStatus& status) {
  Hdf5Paths paths;
  std::getline(lines, paths.mesh), std::getline(lines, paths.boundary);
  std::getline(lines, paths.mesh_shown), std::getline(lines, paths.boundary_shown);
  const ReceivedBlock received = ReceivedBlock::receive();
  std::optional<MeshBlockView> block = received.view();
  if (test_hooks::block_lost(my_rank())) block.reset();
  try {
    write_mesh_hdf5(job_comm(), block.value_or(MeshBlockView()), paths,
                    block ? WriteTrouble::none : WriteTrouble::no_block);
  } catch (const std::exception& e) {
    status.error = e.what();  // rank 0 has the same error and reports it
  }
}

// A worker's side: joins each write rank 0 orders until it says there are no more.
void join_writes(JobStatus& status, RankStats& stats) {
  const AddSeconds timer{stats.write_seconds};
  for (std::string order = broadcast_text(""); !order.empty(); order = broadcast_text("")) {
    std::istringstream lines(order);
    std::string kind;
    std::getline(lines, kind);
    if (kind == "hdf5")
      join_hdf5_write(lines, status);
    else if (kind == kPiecesOrder)
      write_piece_files_sent(lines, stats);
    else
      format_rows_block(lines);
  }
}

// ---------------------------------------------------------------------------------------------
// 2b. With several ranks, the others check the input while rank 0 partitions it, each its share
// (input_share.hpp): rank 0 broadcasts each vertex's share, the faces and the points in parts;
// each rank keeps its share and checks it; ranks 2... send their findings to rank 1 ("F" + the
// findings' bytes, or "E" + an error), which merges them in rank order and sends rank 0 the
// verdict: "" (valid), "I" + an InputError's message, or "E" + another error's.

constexpr std::size_t kStreamPartValues = std::size_t{1} << 19;  // values per broadcast part

// How many shares the input's check has with `size` ranks: one per rank but 0, as many as a
// vertex's 16-bit share can name (ranks beyond check an empty share).
int input_shares(int size) { return std::min(size - 1, 65535); }

// Rank 0's side of one stream.
template <class T>
void broadcast_values(const std::vector<T>& values) {
  for (std::size_t first = 0; first < values.size(); first += kStreamPartValues) {
    const std::size_t n = std::min(kStreamPartValues, values.size() - first);
    bounded(
        [&] { broadcast_bytes(const_cast<T*>(values.data() + first), n * sizeof(T), 0, job_comm(), kWorkerSeconds); });
  }
}

// A checking rank's side: hands each part of `count` values to take(values, n) while the next
// part comes. After take has failed, the rest is received and dropped (rank 0 is waiting for
// every rank to take every part), and the failure is kept.
template <class T, class Take>
void receive_values(std::size_t count, std::exception_ptr& failure, const Take& take) {
  const std::size_t parts = (count + kStreamPartValues - 1) / kStreamPartValues;
  std::vector<T> buffers[2];
  MPI_Request requests[2];
  auto part_size = [&](std::size_t part) { return std::min(kStreamPartValues, count - part * kStreamPartValues); };
  auto start = [&](std::size_t part) {
    std::vector<T>& buffer = buffers[part % 2];
    buffer.resize(part_size(part));
    requests[part % 2] = start_broadcast(buffer.data(), buffer.size() * sizeof(T), 0, job_comm());
  };
  if (parts > 0) start(0);
  for (std::size_t part = 0; part < parts; ++part) {
    if (part + 1 < parts) start(part + 1);
    bounded([&] { return wait_sleeping(requests[part % 2], MPI_STATUS_IGNORE, kRootSeconds); });
    if (failure) continue;
    try {
      take(buffers[part % 2].data(), buffers[part % 2].size());
    } catch (...) {
      failure = std::current_exception();
    }
  }
}

void send_input_for_checks(const SurfaceMesh& input, int size) {
  std::uint64_t counts[2] = {input.points.size(), input.triangles.size()};
  bounded([&] { broadcast_bytes(counts, sizeof counts, 0, job_comm(), kWorkerSeconds); });
  broadcast_values(vertex_shares(input.points, input_shares(size)));
  broadcast_values(input.triangles);
  broadcast_values(input.points);
}

// What a rank that ran out of memory says (its own figures).
std::string out_of_memory_message(int rank) {
  const std::string name = "rank " + std::to_string(rank);
  return name + " ran out of memory (at " + std::to_string(static_cast<long>(own_peak_rss_mb())) +
         " MB; the machine has " + std::to_string(static_cast<long>(available_memory_mb())) +
         " MB available now): use a machine with more memory for " + name;
}

std::string error_message(std::exception_ptr failure, int rank) {
  try {
    std::rethrow_exception(failure);
  } catch (const std::bad_alloc&) {
    return out_of_memory_message(rank);
  } catch (const std::exception& e) {
    return e.what();
  }
}

// Receives this rank's share of the input and checks it: "F" + the findings, or "E" + an error.
std::string check_input_share(int rank, int size, std::uint64_t (&counts)[2]) {
  bounded([&] { broadcast_bytes(counts, sizeof counts, 0, job_comm(), kRootSeconds); });
  std::exception_ptr failure;
  std::optional<InputShareBuilder> builder;
  try {
    builder.emplace(rank - 1, input_shares(size), counts[0], counts[1]);
  } catch (...) {
    failure = std::current_exception();
  }
  receive_values<std::uint16_t>(counts[0], failure, [&](auto* v, std::size_t n) { builder->add_vertex_shares(v, n); });
  receive_values<Triangle>(counts[1], failure, [&](auto* v, std::size_t n) { builder->add_faces(v, n); });
  receive_values<Point3>(counts[0], failure, [&](auto* v, std::size_t n) { builder->add_points(v, n); });
  if (!failure) try {
      test_hooks::share_failure(rank);
      const InputFindings findings = check_share(builder->finish());
      return "F" + std::string(reinterpret_cast<const char*>(&findings), sizeof findings);
    } catch (...) {
      failure = std::current_exception();
    }
  return "E" + error_message(failure, rank);
}

// Rank 1: its own and the other ranks' findings, merged in rank order, judged.
std::string input_verdict(const std::string& own, int size, std::size_t faces) {
  // One deadline for all of them, so rank 0's wait for this verdict (twice the limit) ends later.
  const double limit = input_check_limit(faces), deadline = awake_seconds() + limit;
  InputFindings merged;
  for (int rank = 1; rank < size; ++rank) {
    std::string findings = own;
    if (rank > 1) try {
        findings = recv_bytes(rank, kTagFindings, job_comm(), kMaxChunk, std::max(deadline - awake_seconds(), 1e-3));
      } catch (const Stalled&) {
        return "Erank " + std::to_string(rank) + " has not reported its share of the input check within " +
               std::to_string(static_cast<int>(limit)) + " s (stopped or dead?)";
      }
    if (!findings.empty() && findings[0] == 'E') return findings;
    if (findings.size() != 1 + sizeof(InputFindings) || findings[0] != 'F')
      return "Erank " + std::to_string(rank) + " sent malformed findings of its input check";
    InputFindings share;
    std::memcpy(static_cast<void*>(&share), findings.data() + 1, sizeof share);
    merged.merge(share);
  }
  try {
    judge_input(merged);
  } catch (const InputError& e) {
    return std::string("I") + e.what();
  }
  return "";
}

void check_input_on_rank(int rank, int size, RankStats& stats) {
  const double start = now_seconds();
  std::uint64_t counts[2] = {0, 0};  // vertices, faces
  const std::string findings = check_input_share(rank, size, counts);
  stats.input_check_seconds = now_seconds() - start;
  if (rank > 1) {
    test_hooks::share_stop(rank);
    bounded([&] { return send_bytes(findings, 1, kTagFindings, job_comm(), kMaxChunk, kRootSeconds); });
    return;
  }
  const std::string verdict = input_verdict(findings, size, counts[1]);
  test_hooks::verdict_stop(1);
  bounded([&] { return send_bytes(verdict, 0, kTagVerdict, job_comm(), kMaxChunk, kRootSeconds); });
}

// The CPUs of the ranks on rank 0's node (same processor name), from their affinity masks: rank 0
// borrows them while those ranks wait for its writes (CpuLoan). Empty on the other ranks.
cpu_set_t cpus_of_rank0_node(int rank, int size) {
  struct Where {
    char host[MPI_MAX_PROCESSOR_NAME];
    cpu_set_t cpus;
  };
  Where mine{};
  int length = 0;
  MPI_Get_processor_name(mine.host, &length);
  if (::sched_getaffinity(0, sizeof mine.cpus, &mine.cpus) != 0) CPU_ZERO(&mine.cpus);
  std::vector<Where> all(rank == 0 ? static_cast<std::size_t>(size) : 0);
  bounded([&] { gather_bytes(&mine, sizeof mine, all.data(), 0, job_comm(), collective_limit()); });
  cpu_set_t cpus;
  CPU_ZERO(&cpus);
  for (const Where& where : all)
    if (std::strncmp(where.host, all[0].host, sizeof where.host) == 0) CPU_OR(&cpus, &cpus, &where.cpus);
  return cpus;
}

// What one rank knows about the job as it runs (rank 0's story is in RootRun).
struct RankState {
  int rank = 0, size = 1;
  double start = now_seconds();
  RankStats stats;
  JobStatus status;
  std::map<int, PieceRecord> records;  // piece index -> where and how long it was meshed (rank 0 only)
};

// An error as it crosses ranks: its type and message.
struct ErrorText {
  int type = 0;  // 0 Error, 1 InputError, 2 OptionError, 3 MeshingError, 4 InputMeshingError
  std::string message;
};

ErrorText error_text(std::exception_ptr failure) {
  try {
    std::rethrow_exception(failure);
  } catch (const InputMeshingError& e) {
    return {4, e.what()};
  } catch (const MeshingError& e) {
    return {3, e.what()};
  } catch (const OptionError& e) {
    return {2, e.what()};
  } catch (const InputError& e) {
    return {1, e.what()};
  } catch (const std::exception& e) {
    return {0, e.what()};
  } catch (...) {
    return {0, "unknown error"};
  }
}

// Rank 0's error to every rank (rank 0 is alive: it has just joined an agreement).
void broadcast_error(ErrorText& error, MPI_Comm comm) {
  long long header[2] = {error.type, static_cast<long long>(error.message.size())};
  MPI_Bcast(header, 2, MPI_LONG_LONG, 0, comm);
  error.type = static_cast<int>(header[0]);
  error.message.resize(static_cast<std::size_t>(header[1]));
  MPI_Bcast(error.message.data(), static_cast<int>(header[1]), MPI_CHAR, 0, comm);
}

[[noreturn]] void throw_error(const ErrorText& error) {
  switch (error.type) {
    case 4:
      throw InputMeshingError(Failure{FailureKind::other, -1, {}, error.message});
    case 3:
      throw MeshingError(Failure{FailureKind::other, -1, {}, error.message});
    case 2:
      throw OptionError(error.message);
    case 1:
      throw InputError(error.message);
    default:
      throw Error(error.message);
  }
}

// What an interrupt says on rank 0, before and after the new files are in place.
std::string interrupted_before(const MeshJob& job) {
  return "interrupted (%s): no output written; the files at " + job.output_prefix + " are as they were";
}
std::string interrupted_after(const MeshJob& job) {
  return "%s after the output was published: the new files at " + job.output_prefix + " are complete";
}

// Runs a rank-0 step, turning its exception into the job's error.
template <class Step>
void on_root(RankState& state, Step step) {
  try {
    step();
  } catch (const MeshingError& e) {
    state.status.error = e.what();
    const auto* input_trouble = dynamic_cast<const InputMeshingError*>(&e);
    state.status.meshing_failed = input_trouble == nullptr;
    state.status.split_faces_may_help = input_trouble && input_trouble->split_faces_may_help;
    state.status.out_of_time = e.failure.kind == FailureKind::timed_out;
  } catch (const OptionError& e) {
    state.status.error = e.what();
    state.status.usage_error = true;
  } catch (const std::bad_alloc&) {
    state.status.error = out_of_memory_message(0);
  } catch (const std::exception& e) {
    state.status.error = e.what();
  }
}

// Every rank's figures, gathered on rank 0 (empty elsewhere).
std::vector<RankStats> gather_rank_stats(RankState& state) {
  state.stats.peak_rss_mb = own_peak_rss_mb();
  state.stats.tetgen_child_peak_rss_mb = children_peak_rss_mb();
  std::vector<RankStats> all(state.rank == 0 ? state.size : 0);
  bounded([&] {
    gather_bytes(&state.stats, static_cast<int>(sizeof(RankStats)), all.data(), 0, job_comm(), collective_limit());
    return 0;
  });
  return all;
}

// Only when every rank succeeded does rank 0 publish the files (all at once); then every rank
// learns whether that worked too.
void agree_and_publish(RankState& state, std::optional<RootRun>& root) {
  test_hooks::worker_death(state.rank);
  const std::vector<RankStats> ranks = gather_rank_stats(state);
  bool ok = agree(state.status.error.empty());
  if (ok && root) {
    on_root(state, [&] { root->publish(ranks, state.records, now_seconds() - state.start); });
    state.status.figures = root->figures();
  }
  state.status.ranks = state.size;
  if (ok) ok = agree(state.status.error.empty());
  if (!ok) state.status.exit_code = 1;
}

}  // namespace

std::string library_version() {
  char text[MPI_MAX_LIBRARY_VERSION_STRING];
  int length = 0;
  MPI_Get_library_version(text, &length);
  const std::string version(text, static_cast<std::size_t>(length));
  return version.substr(0, version.find(','));
}

MeshResult mesh_collective(const SurfaceMesh& input, const MeshOptions& options, MPI_Comm comm, StageTimes* times,
                           std::exception_ptr failed_before) {
  const UseComm use(comm);
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  log::set_rank(rank);
  MeshJob job;
  job.options = options;
  RankStats stats;
  MeshResult result;
  std::exception_ptr failure = rank == 0 ? failed_before : nullptr;
  if (rank == 0) {
    if (!failure) try {
        std::map<int, PieceRecord> records;
        RootScheduler scheduler(job, size, stats, records, now_seconds());
        result = mesh_with_retries(input, options, scheduler, times);
      } catch (...) {
        failure = std::current_exception();
      }
    broadcast(kDone);
  } else {
    worker_loop(job, rank, stats);
  }
  if (agree(!failure)) return result;
  // Every rank throws: rank 0 its own error, the others one of the same type with its message.
  ErrorText error = failure ? error_text(failure) : ErrorText{};
  broadcast_error(error, comm);
  if (failure) std::rethrow_exception(failure);
  throw_error(error);
}

JobStatus run_mesh_job(const MeshJob& job) {
  RankState state;
  MPI_Comm_rank(job_comm(), &state.rank);
  MPI_Comm_size(job_comm(), &state.size);
  log::set_rank(state.rank);
  std::optional<RootRun> root;  // rank 0's story
  if (state.rank == 0) root.emplace(job);
  // 1-2. Rank 0 checks where the output goes, then reads and validates the input. An interrupted
  // rank removes its temporary files; rank 0 says which files are in place.
  const InputChecks checks = state.size > 1 ? InputChecks::elsewhere : InputChecks::here;
  const cpu_set_t node_cpus = cpus_of_rank0_node(state.rank, state.size);
  if (root) {
    interrupts::set_messages(interrupted_before(job), interrupted_after(job));
    on_root(state, [&] {
      const CpuLoan loan(node_cpus);  // the ranks on this node wait for the input meanwhile
      root->prepare(checks);
    });
  }
  // Only rank 0 can have failed so far: its exit code goes to every rank (2: a usage error).
  const int start_code = state.status.error.empty() ? 0 : state.status.usage_error ? 2 : 1;
  state.status.exit_code = bounded([&] { return broadcast_int(start_code, 0, job_comm(), collective_limit()); });
  if (state.status.exit_code != 0) return state.status;
  // 2b. The other ranks check the input while rank 0 partitions it (the verdict comes before any piece).
  if (checks == InputChecks::elsewhere) {
    if (root)
      send_input_for_checks(root->input(), state.size);
    else
      check_input_on_rank(state.rank, state.size, state.stats);
  }
  // 3-8. Rank 0 partitions, closes, merges and heals; every rank meshes pieces and regions.
  if (root) {
    on_root(state, [&] {
      RootScheduler scheduler(job, state.size, state.stats, state.records, state.start);
      if (checks == InputChecks::elsewhere) scheduler.expect_input_verdict(root->input().triangles.size());
      root->mesh(scheduler);
    });
    broadcast(kDone);
    // 9. Back to the input's scale, checked and written under temporary names.
    if (state.status.error.empty())
      on_root(state, [&] {
        const AddSeconds timer{state.stats.write_seconds};
        RankWriters writers{write_hdf5_on_every_rank, {}, {}};
        if (state.size > 1) writers.tetgen_lines = write_tetgen_lines_on_every_rank;
        writers.piece_files = [&stats = state.stats](MeshFormat format, const std::vector<PieceFile>& files,
                                                     const PieceArraysOf& arrays_of) {
          PieceFileDealer(format, files, arrays_of, stats).run();
        };
        const CpuLoan loan(node_cpus);  // the ranks on this node only format and wait meanwhile
        root->check_and_write(writers);
      });
    end_writes();
  } else {
    worker_loop(job, state.rank, state.stats);
    join_writes(state.status, state.stats);
  }
  // 10. Every rank agrees; rank 0 publishes and reports.
  agree_and_publish(state, root);
  return state.status;
}

}  // namespace partet::mpi
