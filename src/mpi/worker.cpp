#include "mpi/worker.hpp"

#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>

#include "common/log.hpp"
#include "common/test_hooks.hpp"
#include "io/scratch_bulks.hpp"
#include "io/write_surface.hpp"
#include "mpi/heartbeat.hpp"
#include "mpi/ranks.hpp"
#include "runner/piece_runner.hpp"
#include "runner/serialize.hpp"
#include "stages/merge.hpp"

namespace partet::mpi {
namespace {

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

// Waits for a meshing job's reply, telling rank 0 meanwhile that this rank is alive
// (heartbeat.hpp).
std::string reply_with_heartbeats(PieceJob& job, Heartbeat& heartbeat, int rank) {
  do {
    heartbeat.meshing();
    test_hooks::meshing_stop(rank);
  } while (!job.poll(250));
  return job.take_reply();
}

}  // namespace

// The bulks a worker keeps: of the pieces it meshed and split in rank 0's latest attempt; with
// --scratch in one nameless file in that directory on this rank's node (in memory where it cannot
// write). Their band parts stay here too, in memory (they are small), and the chains' shares cut
// from them wait here until rank 0 takes them.
class KeptBulks {
 public:
  KeptBulks(const std::string& scratch, RankStats& stats) : scratch_(scratch), stats_(stats) { new_attempt(-1); }
  // The ranks that heal the chains take every share before the job ends (rank 0 those it did
  // not heal: RemoteBulks).
  ~KeptBulks() {
    bounded([this] {
      for (auto& [rank, queue] : shares_out_) queue.wait_all();
      return 0;
    });
  }
  std::int32_t attempt() const { return attempt_; }
  // Drops the bulks of earlier attempts (and their files).
  void new_attempt(std::int32_t attempt) {
    attempt_ = attempt;
    bulks_.clear();
    shares_.clear();
    own_shares_.clear();
    bands_.clear();
    chains_.clear();
    on_disk_.reset();
    if (!scratch_.empty()) on_disk_ = std::make_unique<ScratchBulks>(scratch_);
  }
  // A numbered bulk taken out (take) and put back, in memory.
  void keep_numbered(int piece, TetBlock&& bulk) { bulks_[piece] = std::move(bulk); }
  // A bulk to keep: a piece's first (counted), or one taken out and split again (again).
  void keep(int piece, TetBlock&& bulk, bool again = false) {
    if (!again) stats_.bulks_kept += 1;
    if (on_disk_ && on_disk_->put(piece, bulk)) {
      if (!again) stats_.bulks_on_disk += 1;
      bulks_.erase(piece);
      return;
    }
    bulks_[piece] = std::move(bulk);
  }
  void forget(int piece) {
    bulks_.erase(piece);
    shares_.erase(piece);
    bands_.forget(piece);
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
  // The pieces whose bulks it keeps, ascending.
  std::vector<int> pieces() const {
    std::vector<int> kept;
    for (const auto& [piece, bulk] : bulks_) kept.push_back(piece);
    if (on_disk_)
      for (int piece : on_disk_->pieces()) kept.push_back(piece);
    std::sort(kept.begin(), kept.end());
    return kept;
  }
  KeptBandParts& bands() { return bands_; }
  // The seam chains this rank healed and keeps (HealOptions::keep_healed), by the index rank 0
  // gave them; taken once, for the writers or when the band must be welded after all.
  void keep_chain(int index, HealedChain&& chain) { chains_[index] = std::move(chain); }
  std::map<int, HealedChain> take_chains() { return std::move(chains_); }
  // A chain's shares ("": they could not be cut) for the rank that heals it: sent at once (taken
  // in the order pushed), or kept when it is this one.
  void push_shares(int healer, int chain, std::string bytes) {
    if (healer == my_rank()) {
      own_shares_[chain] = std::move(bytes);
      return;
    }
    stats_.bytes_sent += static_cast<double>(bytes.size());
    auto queue = shares_out_.find(healer);
    if (queue == shares_out_.end())
      queue = shares_out_.try_emplace(healer, healer, kTagShare, job_comm(), kRootSeconds).first;
    queue->second.push(std::move(bytes));
  }
  // The shares this rank cut of a chain it heals, once.
  std::string take_own_shares(int chain) {
    const auto it = own_shares_.find(chain);
    if (it == own_shares_.end())
      throw InternalError("this rank kept no shares of seam chain " + std::to_string(chain) + " of its plan");
    std::string bytes = std::move(it->second);
    own_shares_.erase(it);
    return bytes;
  }
  // Lets go of the shares the healing ranks have taken.
  void release_taken_shares() {
    for (auto& [rank, queue] : shares_out_) queue.bytes_waiting();
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
  KeptBandParts bands_;
  std::map<int, SendQueue> shares_out_;    // by healing rank: the chains' shares not yet taken there
  std::map<int, std::string> own_shares_;  // by chain: the shares of those this rank heals
  std::map<int, HealedChain> chains_;      // by index: the chains healed here and kept
};

namespace {

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
               " band tets and " + std::to_string(band.bulk_tets) + " bulk tets kept here");
    kept.keep(piece.index, std::move(band.bulk));
    kept.bands().keep(band);
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
    test_hooks::kept_bulk_stop(my_rank(), "take");
    bytes = serialize_block(*bulk);
  } catch (const std::exception& e) {  // not read back from scratch: rank 0 gets an empty answer and says so
    log::error(e.what());
    bytes.clear();
  }
  AddSeconds timer{stats.send_seconds};
  stats.bytes_sent +=
      static_cast<double>(bounded([&] { return send_bytes(bytes, 0, kTagBulk, job_comm(), kMaxChunk, kRootSeconds); }));
}

// A worker's side of kGrowBand: the owner of the piece grows its band with the bulk it keeps
// (grow_band), keeps the new bulk and sends rank 0 the band ("" when it could not).
void grow_kept_band(KeptBulks& kept, RankStats& stats) {
  const int piece = bounded([] { return broadcast_int(0, 0, job_comm(), kRootSeconds); });
  const int owner = bounded([] { return broadcast_int(0, 0, job_comm(), kRootSeconds); });
  if (owner != my_rank()) return;
  std::string bytes;
  {
    AddSeconds timer{stats.receive_seconds};
    bytes = bounded([] { return recv_bytes(0, kTagBulk, job_comm(), kMaxChunk, kRootSeconds); });
  }
  stats.bytes_received += static_cast<double>(bytes.size());
  test_hooks::kept_bulk_stop(my_rank(), "grow");
  try {
    BandToGrow band = deserialize_band_to_grow(bytes);
    std::string().swap(bytes);
    if (band.index != piece) throw InternalError("rank 0 sent the band of piece " + std::to_string(band.index));
    if (band.band_kept) kept.bands().fill(band);  // (the band part kept here: only the crossings came)
    std::optional<TetBlock> bulk = kept.take(piece);
    if (!bulk) throw InternalError("this rank keeps no mesh of piece " + std::to_string(piece));
    PieceBand grown = grow_band(std::move(band), std::move(*bulk));
    kept.keep(piece, std::move(grown.bulk), true);
    grown.bulk = TetBlock();
    log::debug("piece " + std::to_string(piece) + ": its band grew here by its neighbours' crossings to " +
               std::to_string(grown.band.tets.size()) + " tets");
    kept.bands().keep(grown);
    bytes = serialize_grown_band(grown);
    stats.bands_grown += 1;
  } catch (const std::exception& e) {  // rank 0 gets an empty answer and says so
    log::error("piece " + std::to_string(piece) + ": its band could not grow here: " + e.what());
    kept.forget(piece);
    bytes.clear();
  }
  AddSeconds timer{stats.send_seconds};
  stats.bytes_sent +=
      static_cast<double>(bounded([&] { return send_bytes(bytes, 0, kTagBulk, job_comm(), kMaxChunk, kRootSeconds); }));
}

// A worker's side of kSendBand: the owner of the piece sends its band part (the band to be welded
// after all) and forgets it.
void send_kept_band(KeptBulks& kept, RankStats& stats) {
  const int piece = bounded([] { return broadcast_int(0, 0, job_comm(), kRootSeconds); });
  if (!kept.bands().holds(piece)) return;  // another rank's
  std::string bytes;
  try {
    bytes = serialize_grown_band(kept.bands().take(piece));
  } catch (const std::exception& e) {  // rank 0 gets an empty answer and says so
    log::error("piece " + std::to_string(piece) + ": its band part: " + e.what());
    bytes.clear();
  }
  AddSeconds timer{stats.send_seconds};
  stats.bytes_sent +=
      static_cast<double>(bounded([&] { return send_bytes(bytes, 0, kTagBulk, job_comm(), kMaxChunk, kRootSeconds); }));
}

// The rest of a chain's shares, after those rank 0 gave: from the ranks that keep them (this one
// among them), each taken even after one could not be cut, so that no rank waits on a message
// nobody takes; returns why the chain cannot be welded (none: it can). A rank silent for the
// wait on kept bulks ends the job, named.
std::optional<std::string> take_chain_shares(ChainTask& task, KeptBulks& kept, RankStats& stats) {
  std::optional<std::string> why;
  if (!task.failure.empty()) why = task.failure;
  const std::string chain = "seam chain " + std::to_string(task.index);
  const double limit = test_hooks::kept_bulk_seconds(kWorkerSeconds);
  for (const std::int32_t from : task.share_ranks) {
    const std::string rank = "rank " + std::to_string(from);
    std::optional<std::string> bytes;
    if (from == my_rank()) {
      try {
        bytes = kept.take_own_shares(task.shares_of);
      } catch (const std::exception& e) {
        if (!why) why = e.what();
        continue;
      }
    } else {
      AddSeconds timer{stats.receive_seconds};
      try {
        bytes = recv_bytes(from, kTagShare, job_comm(), kMaxChunk, limit);
      } catch (const Stalled&) {
        abort_job(rank + " did not send its shares of " + chain + " of the band parts it kept within " +
                  std::to_string(static_cast<int>(limit)) + " s (stopped or dead?)");
      }
      stats.bytes_received += static_cast<double>(bytes->size());
    }
    if (why) continue;
    if (bytes->empty()) {
      why = rank + " could not cut its shares of " + chain + " from the band parts it kept (its log says why)";
      continue;
    }
    try {
      for (ChainShare& share : deserialize_chain_shares(*bytes)) {
        if (share.chain != task.shares_of) throw InternalError(rank + " sent the shares of another seam chain");
        task.chain.shares.push_back(std::move(share));
      }
      stats.chain_shares_direct += 1;
    } catch (const std::exception& e) {
      why = e.what();
    }
  }
  return why;
}

// A worker's side of kSendChains: the seam chains it healed and kept, back to rank 0 in full (the
// band must be welded after all): how many, then each.
void send_kept_chains(KeptBulks& kept, RankStats& stats) {
  std::map<int, HealedChain> chains = kept.take_chains();
  AddSeconds timer{stats.send_seconds};
  const auto send = [&](const std::string& bytes) {
    stats.bytes_sent += static_cast<double>(
        bounded([&] { return send_bytes(bytes, 0, kTagBulk, job_comm(), kMaxChunk, kRootSeconds); }));
  };
  send(std::to_string(chains.size()));
  for (auto& [index, chain] : chains) {
    stats.chains_kept -= 1, stats.chain_tets_kept -= static_cast<double>(chain.tets.size());
    send(serialize_chain_outcome(index, chain));
    chain = HealedChain();
  }
}

// A worker's part of seam healing: welds a chain of the seams from its pieces' shares (rank 0's
// in the task, the others' from the ranks that keep them) and heals it whole, its regions in
// TetGen processes here one after another, and sends rank 0 the healed chain or its failure.
// Its heartbeats go on from the start to the reply (heartbeat.hpp).
void heal_chain_for_root(std::string&& bytes, std::uint64_t task, const MeshJob& job, int rank, KeptBulks& kept,
                         RankStats& stats) {
  ChainTask chain = deserialize_chain_task(bytes);
  std::string().swap(bytes);
  const PieceRunner runner(chain.tetgen, job.options.run);
  Heartbeat heartbeat(job_comm(), task);
  heartbeat.meshing();
  test_hooks::chain_stop(rank);
  const RegionMesher here = [&](const std::vector<PieceSurface>& regions) {
    std::vector<PieceOutcome> outcomes;
    for (const PieceSurface& region : regions)
      outcomes.push_back(deserialize_outcome(reply_with_heartbeats(*runner.start(region), heartbeat, rank)));
    return outcomes;
  };
  HealedChain healed;
  const std::int32_t index = chain.index;
  const std::vector<int> planes = chain.chain.split.planes;
  try {
    AddSeconds timer{stats.region_seconds};
    if (const std::optional<std::string> why = take_chain_shares(chain, kept, stats)) {
      log::warning("seam chain " + std::to_string(index) + " could not be gathered from its pieces' shares: " + *why);
      healed.failure = Failure(FailureKind::other, -1, planes, *why);
    } else {
      healed = heal_chain(weld_chain(std::move(chain.chain)), chain.heal, here);
    }
  } catch (const std::bad_alloc&) {
    healed = HealedChain();
    healed.failure = Failure(FailureKind::other, -1, planes, out_of_memory_message(rank));
  } catch (const std::exception& e) {
    healed = HealedChain();
    healed.failure = Failure(FailureKind::other, -1, planes, e.what());
  }
  const bool keep = chain.heal.keep_healed && !healed.failure;
  chain = ChainTask();
  heartbeat.done();
  const std::string reply = serialize_chain_outcome(index, keep ? kept_elsewhere(healed, rank, index) : healed);
  if (keep) {
    stats.chains_kept += 1, stats.chain_tets_kept += static_cast<double>(healed.tets.size());
    kept.keep_chain(index, std::move(healed));
  }
  AddSeconds timer{stats.send_seconds};
  stats.bytes_sent += static_cast<double>(
      bounded([&] { return send_bytes(reply, 0, kTagReply, job_comm(), kMaxChunk, kRootSeconds); }));
}

// A worker's side of kCutShares: the shares of every chain of the band parts it keeps, cut now
// and sent in rank 0's order straight to the rank that heals the chain (kept here when it is this
// one), to take as it welds the chain (kTagShare). A chain whose shares could not be cut gets an
// empty message: its healing rank takes that chain for failed.
void cut_kept_shares(KeptBulks& kept, RankStats& stats) {
  AddSeconds timer{stats.share_cut_seconds};
  for (const auto& [index, chain] : kept.take_chains())  // (a new round of chains: an earlier attempt's go)
    stats.chains_kept -= 1, stats.chain_tets_kept -= static_cast<double>(chain.tets.size());
  std::vector<BandPartPlan> plans, here;
  std::vector<int> order, healers;
  const std::string plan = bounded([] { return recv_bytes(0, kTagBulk, job_comm(), kMaxChunk, kRootSeconds); });
  stats.bytes_received += static_cast<double>(plan.size());
  deserialize_share_plan(plan, plans, order, healers);
  std::set<int> chains;  // those whose healing ranks wait for shares from this rank
  for (BandPartPlan& plan : plans) {
    if (!kept.bands().holds(plan.place.piece)) continue;
    for (const int chain : chains_of(plan)) chains.insert(chain);
    here.push_back(std::move(plan));
  }
  test_hooks::kept_bulk_stop(my_rank(), "shares");
  std::set<int> sent;
  try {
    test_hooks::kept_shares_failure(my_rank());
    kept.bands().cut_shares(here, order, [&](int chain, std::vector<ChainShare>&& shares) {
      kept.push_shares(healers.at(static_cast<std::size_t>(chain)), chain, serialize_chain_shares(shares));
      sent.insert(chain);
    });
  } catch (const std::exception& e) {
    log::error(std::string("the seam chains' shares of the band parts kept here: ") + e.what());
    for (const int chain : order)
      if (chains.count(chain) && !sent.count(chain))
        kept.push_shares(healers.at(static_cast<std::size_t>(chain)), chain, "");
  }
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

// A worker's side of kLinkBulks: the links of every bulk it keeps, numbered (they stay here).
void send_bulk_links(KeptBulks& kept, RankStats& stats) {
  const std::int32_t input_vertices = bounded([] { return broadcast_int(0, 0, job_comm(), kRootSeconds); });
  test_hooks::kept_bulk_stop(my_rank(), "links");
  std::vector<std::pair<int, BlockLinks>> links;
  try {
    for (int piece : kept.pieces()) {
      std::optional<TetBlock> bulk = kept.take(piece);
      std::vector<std::int32_t> label;
      links.emplace_back(piece,
                         block_links(bulk->tets, bulk->ids, bulk->neighbours, false, input_vertices, bulk->rim, label));
      kept.keep_numbered(piece, std::move(*bulk));
    }
  } catch (const std::exception& e) {  // rank 0 misses this rank's links and says so
    log::error(std::string("the links of the kept bulks: ") + e.what());
    links.clear();
  }
  const std::string bytes = serialize_bulk_links(links);
  AddSeconds timer{stats.send_seconds};
  stats.bytes_sent +=
      static_cast<double>(bounded([&] { return send_bytes(bytes, 0, kTagBulk, job_comm(), kMaxChunk, kRootSeconds); }));
}

}  // namespace

CapOutcome triangulated(const CapBorder& border, RankStats& stats, const std::function<void()>& before) {
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

Worker::Worker(const MeshJob& job, int rank, RankStats& stats) : job_(job), rank_(rank), stats_(stats) {
  if (!job.options.scratch.empty()) remove_stale_scratch(job.options.scratch);  // this node's dead runs'
  kept_ = std::make_unique<KeptBulks>(job.options.scratch, stats);
}

Worker::~Worker() = default;

std::map<int, HealedChain> Worker::take_kept_chains() { return kept_->take_chains(); }

std::map<int, TetBlock> Worker::take_kept_bulks() {
  std::map<int, TetBlock> taken;
  for (int piece : kept_->pieces())
    if (std::optional<TetBlock> bulk = kept_->take(piece)) taken.emplace(piece, std::move(*bulk));
  return taken;
}

void worker_loop(const MeshJob& job, int rank, RankStats& stats) { Worker(job, rank, stats).mesh_rounds(); }

void Worker::mesh_rounds() {
  const MeshJob& job = job_;
  const int rank = rank_;
  RankStats& stats = stats_;
  KeptBulks& kept = *kept_;
  std::uint64_t tasks = 0;  // taken: pieces, regions and caps, as rank 0 counts them
  for (Command command = receive_command(); command != kDone; command = receive_command()) {
    if (command == kSendBulk) {
      send_kept_bulk(kept, stats);
      continue;
    }
    if (command == kGrowBand) {
      grow_kept_band(kept, stats);
      continue;
    }
    if (command == kNumberBulks) {
      number_kept_bulks(kept, stats);
      continue;
    }
    if (command == kLinkBulks) {
      send_bulk_links(kept, stats);
      continue;
    }
    if (command == kSendBand) {
      send_kept_band(kept, stats);
      continue;
    }
    if (command == kCutShares) {
      cut_kept_shares(kept, stats);
      continue;
    }
    if (command == kSendChains) {
      send_kept_chains(kept, stats);
      continue;
    }
    for (;;) {
      std::string bytes;
      {
        AddSeconds timer{stats.receive_seconds};
        bytes = bounded([] { return recv_bytes(0, kTagPiece, job_comm(), kMaxChunk, kRootSeconds); });
      }
      stats.bytes_received += static_cast<double>(bytes.size());
      kept.release_taken_shares();
      if (bytes.empty()) break;
      ++tasks;
      if (task_kind(bytes) == TaskKind::cap) {
        build_cap_for_root(bytes, rank, stats);
        continue;
      }
      if (task_kind(bytes) == TaskKind::chain) {
        heal_chain_for_root(std::move(bytes), tasks, job, rank, kept, stats);
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
          if (!region) test_hooks::piece_failure(piece.index, piece.triangles.size(), rank);
        });
        Heartbeat heartbeat(job_comm(), tasks);
        reply = reply_with_heartbeats(*job, heartbeat, rank);
        heartbeat.done();
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
  // No chain is welded after the last round: the band parts kept for the chains go before the
  // writes, which need only the bulks.
  kept.bands().clear();
}

}  // namespace partet::mpi
