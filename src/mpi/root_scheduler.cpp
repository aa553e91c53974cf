#include "mpi/root_scheduler.hpp"

#include <algorithm>
#include <chrono>
#include <deque>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "common/awake_clock.hpp"
#include "common/balanced_ranks.hpp"
#include "common/log.hpp"
#include "common/test_hooks.hpp"
#include "mpi/heartbeat.hpp"
#include "mpi/input_check_ranks.hpp"
#include "mpi/ranks.hpp"
#include "mpi/worker.hpp"
#include "partet/errors.hpp"
#include "runner/isolated_run.hpp"
#include "runner/serialize.hpp"

namespace partet::mpi {
namespace {

// How long rank 0 sleeps between looks at MPI when idle: the pause doubles from the shortest to
// the longest while nothing happens, so replies to small regions (seams, polish) are taken at
// once and long pieces still leave the core to the TetGen processes.
constexpr std::chrono::microseconds kShortestIdle{50}, kLongestIdle{5000};

// The bulks of the pieces split where they were meshed (split_where_meshed), kept by the ranks
// that meshed them until the welder needs them. Before the assembly rank 0 broadcasts
// kNumberBulks and the numbering's shares of the kept bulks: each owner numbers its own at once
// (while rank 0 numbers those it keeps). Then, for each, rank 0 broadcasts kSendBulk and the
// piece's index, and its owner sends the bulk ("" if it has none). A band its neighbours' crossings
// grow grows where the bulk is: rank 0 broadcasts kGrowBand, the piece and its owner, sends the
// owner the band, and gets the band grown ("" when it could not). The workers wait for commands
// then. The owners keep the band parts too: their crossings alone travel to grow them (the band
// part stays with its owner), and before the chains are welded rank 0 broadcasts kCutShares and
// the plan with the rank that heals each chain: each owner cuts its shares of every chain and
// sends them at once straight to that rank, one message per chain in rank 0's order, which the
// healing rank takes as it welds the chain (rank 0 those of its own chains). A band part comes
// back (kSendBand) only when the band must be welded after all.
class RemoteBulks : public BulkStore {
 public:
  explicit RemoteBulks(RankStats& stats) : stats_(stats), limit_(test_hooks::kept_bulk_seconds(kWorkerSeconds)) {}
  // The owners wait for rank 0 to take every share they sent before they end.
  ~RemoteBulks() override { take_pending_shares(); }
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
  // Every worker makes the links of the bulks it keeps, numbered, and sends them, by piece.
  void ask_links(std::int32_t input_vertices) override {
    broadcast(kLinkBulks);
    bounded([&] { return broadcast_int(input_vertices, 0, job_comm(), collective_limit()); });
  }
  std::vector<std::pair<int, BlockLinks>> links() override {
    int size = 1;
    MPI_Comm_size(job_comm(), &size);
    std::vector<std::pair<int, BlockLinks>> all;
    for (int rank = 1; rank < size; ++rank)
      for (auto& links : deserialize_bulk_links(reply_from(rank, "send the links of the bulks it keeps")))
        all.push_back(std::move(links));
    return all;
  }
  bool grows_bands() const override { return true; }
  PieceBand grow(BandToGrow&& band) override {
    const int piece = band.index;
    const int rank = owner_of(piece);
    broadcast(kGrowBand);
    bounded([&] { return broadcast_int(piece, 0, job_comm(), collective_limit()); });
    bounded([&] { return broadcast_int(rank, 0, job_comm(), collective_limit()); });
    const std::string what = "grow the band of piece " + std::to_string(piece);
    std::string bytes = serialize_band_to_grow(band);
    band = BandToGrow();
    try {
      AddSeconds timer{stats_.send_seconds};
      stats_.bytes_sent += static_cast<double>(send_bytes(bytes, rank, kTagBulk, job_comm(), kMaxChunk, limit_));
    } catch (const Stalled&) {
      silent(rank, what);
    }
    AddSeconds timer{stats_.receive_seconds};
    bytes = reply_from(rank, what);
    if (bytes.empty())
      throw InternalError("rank " + std::to_string(rank) + " could not grow the band of piece " +
                          std::to_string(piece) + " with the mesh it kept");
    return deserialize_grown_band(bytes);
  }
  // Every worker sends back the seam chains it healed and kept: how many, then each.
  std::vector<std::pair<int, HealedChain>> take_chains() override {
    broadcast(kSendChains);
    int size = 1;
    MPI_Comm_size(job_comm(), &size);
    std::vector<std::pair<int, HealedChain>> all;
    for (int rank = 1; rank < size; ++rank) {
      const std::string what = "send back the seam chains it healed";
      const std::string count = reply_from(rank, what);
      for (unsigned long i = 0, n = std::stoul(count); i < n; ++i) {
        std::int32_t index = 0;
        HealedChain chain = deserialize_chain_outcome(reply_from(rank, what), index);
        all.emplace_back(index, std::move(chain));
      }
    }
    return all;
  }
  PieceBand take_band(int piece) override {
    return deserialize_grown_band(ask_owner(kSendBand, piece, "the band part of piece " + std::to_string(piece)));
  }
  void cut_shares(const std::vector<BandPartPlan>& plans, const std::vector<int>& order,
                  const std::vector<int>& healers) override {
    take_pending_shares();
    std::map<int, std::set<int>> ranks;                // by chain: those with a share of it
    std::map<int, std::vector<BandPartPlan>> of_rank;  // the plans of the band parts each rank keeps
    for (const BandPartPlan& plan : plans) {
      const int owner = owner_of(plan.place.piece);
      for (const int chain : chains_of(plan)) ranks[chain].insert(owner);
      of_rank[owner].push_back(plan);
    }
    broadcast(kCutShares);
    int size = 1;
    MPI_Comm_size(job_comm(), &size);
    for (int rank = 1; rank < size; ++rank)  // (to each its own: a stopped rank is named, not waited for)
      try {
        stats_.bytes_sent += static_cast<double>(send_bytes(serialize_share_plan(of_rank[rank], order, healers), rank,
                                                            kTagBulk, job_comm(), kMaxChunk, limit_));
      } catch (const Stalled&) {
        silent(rank, "take the plan of the seam chains' shares");
      }
    elsewhere_.assign(order.size(), ChainElsewhere());
    for (std::size_t j = 0; j < order.size(); ++j) {
      const int chain = order[j];
      elsewhere_[j].chain = chain;
      const auto it = ranks.find(chain);
      if (it == ranks.end()) continue;
      std::vector<int> with_shares(it->second.begin(), it->second.end());
      if (healers.at(static_cast<std::size_t>(chain)) == 0)
        pending_.push_back({chain, std::move(with_shares)});
      else
        elsewhere_[j].ranks.assign(with_shares.begin(), with_shares.end());
    }
  }
  // The chain handed out j-th: its number in the owners' plan and the ranks that send its shares
  // to the rank that heals it (none when cut_shares was not asked; cleared by end_chains).
  std::pair<std::int32_t, std::vector<std::int32_t>> shares_elsewhere(std::size_t j) const {
    if (j >= elsewhere_.size()) return {-1, {}};
    return {elsewhere_[j].chain, elsewhere_[j].ranks};
  }
  void end_chains() { elsewhere_.clear(); }
  double limit() const { return limit_; }
  // Asked for in the order given to cut_shares (the ranks sent them in that order). Every rank's
  // message is taken before an empty one (a rank that could not cut them) throws.
  std::vector<ChainShare> shares(int chain) override {
    const auto it =
        std::find_if(pending_.begin(), pending_.end(), [&](const PendingChain& c) { return c.chain == chain; });
    if (it == pending_.end()) return {};
    if (it != pending_.begin())
      throw InternalError("seam chain " + std::to_string(chain) + " was asked for out of order");
    const PendingChain pending = std::move(*it);
    pending_.pop_front();
    std::vector<std::string> sent;
    for (const int rank : pending.ranks) {
      AddSeconds timer{stats_.receive_seconds};
      sent.push_back(reply_from(
          rank, "send its shares of seam chain " + std::to_string(chain) + " of the band parts it kept", kTagShare));
    }
    std::vector<ChainShare> shares;
    for (std::size_t i = 0; i < sent.size(); ++i) {
      if (sent[i].empty())
        throw InternalError("rank " + std::to_string(pending.ranks[i]) + " could not cut its shares of seam chain " +
                            std::to_string(chain) + " from the band parts it kept (its log says why)");
      for (ChainShare& share : deserialize_chain_shares(sent[i])) shares.push_back(std::move(share));
      std::string().swap(sent[i]);
    }
    return shares;
  }
  TetBlock take(int piece) override {
    const std::string bytes = ask_owner(kSendBulk, piece, "the mesh of piece " + std::to_string(piece));
    owners_.erase(piece);
    return deserialize_block(bytes);
  }

 private:
  int owner_of(int piece) const {
    const auto owner = owners_.find(piece);
    if (owner == owners_.end()) throw InternalError("no rank keeps the bulk of piece " + std::to_string(piece));
    return owner->second;
  }
  // Broadcasts `command` and `piece`, and returns the answer of the rank keeping `what` of the
  // piece; an empty answer (it no longer keeps it) is an internal error.
  std::string ask_owner(Command command, int piece, const std::string& what) {
    const int rank = owner_of(piece);
    broadcast(command);
    bounded([&] { return broadcast_int(piece, 0, job_comm(), collective_limit()); });
    AddSeconds timer{stats_.receive_seconds};
    std::string bytes = reply_from(rank, "send " + what + " it kept");
    if (bytes.empty()) throw InternalError("rank " + std::to_string(rank) + " no longer keeps " + what);
    return bytes;
  }
  // Ends the job: `rank` did not do `what` within the wait on kept bulks.
  [[noreturn]] void silent(int rank, const std::string& what) const {
    abort_job("rank " + std::to_string(rank) + " did not " + what + " within " +
              std::to_string(static_cast<int>(limit_)) + " s (stopped or dead?)");
  }
  // The shares sent and not taken (a heal that ended early): taken and dropped, so that the owners
  // can end; an owner silent for limit_ is left alone (the job is ending anyway).
  void take_pending_shares() {
    for (const PendingChain& chain : pending_)
      for (const int rank : chain.ranks) try {
          stats_.bytes_received +=
              static_cast<double>(recv_bytes(rank, kTagShare, job_comm(), kMaxChunk, limit_).size());
        } catch (const Stalled&) {
          log::error("rank " + std::to_string(rank) + " did not send its shares of seam chain " +
                     std::to_string(chain.chain));
        }
    pending_.clear();
  }
  // What `rank` sends back on kTagBulk (or `tag`); silent for longer than limit_, it ends the job.
  std::string reply_from(int rank, const std::string& what, int tag = kTagBulk) {
    std::string bytes;
    try {
      bytes = recv_bytes(rank, tag, job_comm(), kMaxChunk, limit_);
    } catch (const Stalled&) {
      silent(rank, what);
    }
    stats_.bytes_received += static_cast<double>(bytes.size());
    return bytes;
  }
  RankStats& stats_;
  double limit_;               // how long a rank may take to answer a command on its bulks
  std::map<int, int> owners_;  // piece -> the rank keeping its bulk
  struct PendingChain {
    int chain;
    std::vector<int> ranks;  // those whose shares of it rank 0 has not taken yet, ascending
  };
  std::deque<PendingChain> pending_;  // in the order the ranks send them
  struct ChainElsewhere {
    std::int32_t chain = -1;
    std::vector<std::int32_t> ranks;  // those sending their shares of it to its healing rank
  };
  std::vector<ChainElsewhere> elsewhere_;  // by place in the order, for the chains healed elsewhere
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

  // Seam healing chain by chain: each chain is healed whole (its regions meshed there) by the
  // rank planned for it (chain_ranks), which the owners of its band parts send their shares to;
  // a worker takes the next of its chains as soon as it is free, and this rank heals its own,
  // looking at MPI while its regions are meshed.
  bool heals_chains_on_ranks() const override { return size_ > 1; }

  std::vector<int> chain_ranks(const std::vector<std::size_t>& tets) override {
    chain_ranks_ = balanced_ranks(tets, size_);
    return chain_ranks_;
  }

  std::vector<HealedChain> heal_chains(std::size_t count, const ChainCutter& cut_out, const HealOptions& heal,
                                       const TetgenOptions& tetgen) override {
    if (chain_ranks_.size() != count) throw InternalError("the seam chains were handed out without a plan");
    begin_round(tetgen);
    chain_round_.emplace(ChainRound{&cut_out, heal, tetgen, {}, std::vector<HealedChain>(count), 0, {}});
    for (std::size_t i = 0; i < count; ++i) chain_round_->queues[chain_ranks_[i]].push_back(i);
    std::chrono::microseconds idle = kShortestIdle;
    while (chain_round_->done < count) {
      dispatch_chains();
      bool replied = false;
      while (receive_reply()) replied = true;
      check_workers_answer();
      if (chain_round_->waiting(0)) {
        heal_chain_here();
        idle = kShortestIdle;
      } else {
        idle = replied ? kShortestIdle : sleep_idle(idle);
      }
    }
    for (int w = 1; w < size_; ++w) send_piece(w, nullptr);  // round over
    take_alive();
    std::vector<HealedChain> healed = std::move(chain_round_->healed);
    chain_round_.reset();
    chain_ranks_.clear();
    remote_.end_chains();
    return healed;
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

  // Each free worker takes the next of the chains planned for it.
  void dispatch_chains() {
    for (auto it = idle_.begin(); it != idle_.end();) {
      const int worker = *it;
      if (!chain_round_->waiting(worker)) {
        ++it;
        continue;
      }
      it = idle_.erase(it);
      send_chain(worker);
    }
  }

  struct GatheredChain {
    std::size_t index;  // the chain's
    ChainShares shares;
    std::optional<std::string> failure;  // why it could not be gathered here (then no shares)
  };

  // The next chain planned for `rank`, gathered (the one gathered ahead, if any); none when none
  // is left.
  std::optional<GatheredChain> next_chain(int rank) {
    std::optional<GatheredChain> next;
    if (const auto ahead = chain_round_->ahead.find(rank); ahead != chain_round_->ahead.end()) {
      next = std::move(ahead->second);
      chain_round_->ahead.erase(ahead);
    } else if (std::deque<std::size_t>& queue = chain_round_->queues[rank]; !queue.empty()) {
      const std::size_t chain = queue.front();
      queue.pop_front();
      next = GatheredChain{chain, {}, std::nullopt};
      next->failure = error_of([&] { next->shares = (*chain_round_->cut_out)(chain); });
      if (next->failure) warn_unmade(chain, "gathered", *next->failure);
    }
    return next;
  }

  // While this rank heals a chain: the next chain of a busy worker gathered now, so that it gets
  // it at once when it is free.
  void gather_ahead() {
    for (const auto& [worker, busy] : busy_)
      if (!chain_round_->ahead.count(worker) && !chain_round_->queues[worker].empty()) {
        std::optional<GatheredChain> next = next_chain(worker);
        log::debug("seam chain " + std::to_string(next->index) + " gathered ahead for rank " + std::to_string(worker));
        chain_round_->ahead.emplace(worker, std::move(*next));
        return;
      }
  }

  // A chain takes as long as its regions: its deadline is the longest rank 0 waits for anything,
  // from the worker's latest heartbeat (take_alive); its heartbeats, from the start, tell a
  // stopped or dead rank within kSilentSeconds. The worker takes the rest of its shares from the
  // ranks that keep them; a chain that could not be gathered here still goes, so that the worker
  // takes them, and fails there.
  void send_chain(int worker) {
    std::optional<GatheredChain> cut = next_chain(worker);  // (its gathering is not sending: the log has it)
    if (!cut) {
      idle_.push_back(worker);
      return;
    }
    AddSeconds timer{stats_.send_seconds};
    const std::size_t chain = cut->index;
    ChainTask task;
    task.index = static_cast<std::int32_t>(chain);
    task.chain = std::move(cut->shares);
    task.heal = chain_round_->heal;
    task.tetgen = chain_round_->tetgen;
    std::tie(task.shares_of, task.share_ranks) = remote_.shares_elsewhere(chain);
    task.failure = cut->failure.value_or("");
    cut.reset();
    const std::string bytes = serialize_chain_task(task);
    task = ChainTask();
    busy_[worker] = {awake_seconds() + kRootSeconds, static_cast<int>(chain), false, ++tasks_[worker]};
    busy_[worker].chain = true;
    account_meshing();
    const double limit = remote_.limit();  // (as for the shares it sends the chain's rank)
    try {
      stats_.bytes_sent += static_cast<double>(send_bytes(bytes, worker, kTagPiece, job_comm(), kMaxChunk, limit));
    } catch (const Stalled&) {
      abort_job("rank " + std::to_string(worker) + " did not take seam chain " + std::to_string(chain) + " within " +
                std::to_string(static_cast<int>(limit)) + " s (stopped or dead?)");
    }
  }

  // What `work` threw, as a chain's failure says it (none when it did not throw).
  template <class Work>
  static std::optional<std::string> error_of(Work&& work) {
    try {
      work();
    } catch (const std::bad_alloc&) {
      return out_of_memory_message(0);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::nullopt;
  }

  // A chain that could not be gathered or welded from its pieces' shares failed (its seams then
  // heal over the whole mesh); the log says why.
  static void warn_unmade(std::size_t chain, const char* how, const std::string& why) {
    log::warning("seam chain " + std::to_string(chain) + " could not be " + how + " from its pieces' shares: " + why);
  }
  static HealedChain failed_chain(std::vector<int> planes, const std::string& why) {
    HealedChain failed;
    failed.failure = Failure(FailureKind::other, -1, std::move(planes), why);
    return failed;
  }

  // Heals the next chain here, its regions in TetGen processes one after another; between looks
  // at a region, the replies that came are taken and free workers get the next chains.
  void heal_chain_here() {
    const PieceRunner runner(chain_round_->tetgen, job_.options.run);
    const RegionMesher here = [&](const std::vector<PieceSurface>& regions) {
      std::vector<PieceOutcome> outcomes;
      for (const PieceSurface& region : regions) {
        const std::unique_ptr<PieceJob> run = runner.start(region, [] {});
        while (!run->poll(2)) {
          while (receive_reply()) {
          }
          check_workers_answer();
          dispatch_chains();
          gather_ahead();
        }
        outcomes.push_back(deserialize_outcome(run->take_reply()));
      }
      return outcomes;
    };
    std::optional<GatheredChain> cut = next_chain(0);
    if (!cut) return;
    const std::size_t chain = cut->index;
    if (cut->failure) {  // (a chain failed is not an end to the round the other ranks are in)
      chain_done(chain, failed_chain({}, *cut->failure), 0);
      return;
    }
    AddSeconds timer{stats_.region_seconds};
    healing_here_ = true;
    account_meshing();
    HealedChain healed = weld_and_heal(chain, std::move(cut->shares), chain_round_->heal, here);
    cut.reset();
    healing_here_ = false;
    account_meshing();
    chain_done(chain, std::move(healed), 0);
  }

  // The chain welded and healed here; one that cannot be welded failed, as one whose shares
  // could not be gathered.
  static HealedChain weld_and_heal(std::size_t chain, ChainShares&& shares, const HealOptions& heal,
                                   const RegionMesher& here) {
    std::vector<int> planes = shares.split.planes;
    ChainBand band;
    const std::optional<std::string> why = error_of([&] { band = weld_chain(std::move(shares)); });
    if (!why) return heal_chain(std::move(band), heal, here);
    warn_unmade(chain, "welded", *why);
    return failed_chain(std::move(planes), *why);
  }

  void chain_done(std::size_t chain, HealedChain&& healed, int rank) {
    const bool failed = healed.failure.has_value();
    chain_round_->healed.at(chain) = std::move(healed);
    ++chain_round_->done;
    log::info("seam chains " + std::to_string(chain_round_->done) + "/" + std::to_string(chain_round_->healed.size()) +
              " healed (chain " + std::to_string(chain) + " on rank " + std::to_string(rank) +
              (failed ? ", failed)" : ")"));
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
                  std::to_string(static_cast<int>(silence_limit_)) +
                  (busy.chain ? " s while healing seam chain " : " s while meshing piece ") +
                  std::to_string(busy.piece) + " (stopped, hung, or its node lost?)");
      if (now > busy.deadline)
        abort_job("rank " + std::to_string(worker) + " has not answered for " +
                  (busy.cap     ? "the cap of plane "
                   : busy.chain ? "seam chain "
                                : "piece ") +
                  std::to_string(busy.piece) + " within its time limit (stopped or dead?)");
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
      // A chain heals as long as its regions take, one after another: while it is heard, its
      // deadline moves on, and its silence tells a stopped rank.
      if (busy->second.chain) busy->second.deadline = busy->second.heard + kRootSeconds;
    }
  }

  void start_own_piece() {
    own_position_ = take_next();
    const PieceSurface& piece = *pieces_[own_position_];
    record(piece, 0);
    own_start_ = now_seconds();
    if (!piece.seam_region) dump_piece(job_, piece);
    own_ = runner_.start(piece, [&piece] {
      if (!piece.seam_region) test_hooks::piece_failure(piece.index, piece.triangles.size(), 0);
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
      if (is_chain_outcome(reply)) {
        std::int32_t chain = 0;
        HealedChain healed = deserialize_chain_outcome(reply, chain);
        if (!chain_round_ || busy_.at(worker).piece != chain)
          throw InternalError("rank " + std::to_string(worker) + " sent a seam chain it was not given");
        idle_.push_back(worker);
        busy_.erase(worker);
        account_meshing();
        chain_done(static_cast<std::size_t>(chain), std::move(healed), worker);
        return true;
      }
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
    meshing_ = busy_.size() + (own_ || healing_here_ ? 1 : 0);
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
          outcome.band ? (outcome.band->band_kept ? outcome.band->band_tet_count
                                                  : static_cast<std::int64_t>(outcome.band->band.tets.size())) +
                             outcome.band->bulk_tets
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
    bool chain = false;    // a chain of the seams to heal (piece: its index)
  };
  std::map<int, Busy> busy_;            // workers with a piece
  std::map<int, std::uint64_t> tasks_;  // per worker: the tasks sent (pieces, regions, caps)
  std::size_t remaining_ = 0;
  std::deque<int> cap_queue_;       // planes whose caps nobody builds yet
  std::map<int, CapOutcome> caps_;  // by plane: built, not yet taken by cap()
  struct ChainRound {
    const ChainCutter* cut_out;
    HealOptions heal;
    TetgenOptions tetgen;
    std::map<int, std::deque<std::size_t>> queues;  // by rank: its chains not handed out yet
    std::vector<HealedChain> healed;
    std::size_t done;
    // By worker: its next chain, gathered while this rank heals one (gather_ahead).
    std::map<int, GatheredChain> ahead;
    bool waiting(int rank) const {
      const auto queue = queues.find(rank);
      return ahead.count(rank) || (queue != queues.end() && !queue->second.empty());
    }
  };
  std::vector<int> chain_ranks_;           // the rank planned for each chain (by place)
  std::optional<ChainRound> chain_round_;  // while heal_chains runs
  bool healing_here_ = false;              // this rank heals a chain
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

}  // namespace

std::unique_ptr<PieceScheduler> root_scheduler(const MeshJob& job, int size, RankStats& stats,
                                               std::map<int, PieceRecord>& records, double job_start,
                                               std::optional<std::size_t> input_verdict_faces) {
  auto scheduler = std::make_unique<RootScheduler>(job, size, stats, records, job_start);
  if (input_verdict_faces) scheduler->expect_input_verdict(*input_verdict_faces);
  return scheduler;
}

}  // namespace partet::mpi
