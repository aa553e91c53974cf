#include "mpi/spread_tetgen_files.hpp"

#include <algorithm>
#include <cstring>
#include <deque>
#include <exception>
#include <map>
#include <vector>

#include "common/log.hpp"
#include "common/test_hooks.hpp"
#include "io/buffered_file.hpp"
#include "io/tetgen_files.hpp"
#include "mpi/write_messages.hpp"
#include "partet/errors.hpp"
#include "runner/serialize.hpp"

namespace partet::mpi {
namespace {

// Rows formatted and sent at a time: 10-16 MB of text.
constexpr std::size_t kRowsPerChunk = std::size_t{1} << 18;
// Text a rank formats ahead of rank 0, while rank 0 writes the runs before its own: its runs are
// then formatted while rank 0 formats its own, not after.
constexpr std::size_t kReadAheadBytes = std::size_t{256} << 20;

// A file's order to one rank: "F", the file, then the pieces of its runs (int32 each), in row order.
std::string file_order(TetgenFile file, const std::vector<std::int32_t>& pieces) {
  std::string order = "F";
  order += static_cast<char>('0' + static_cast<int>(file));
  order.append(bytes_of(run_of(pieces)));
  return order;
}

// Calls f(from, count) for each chunk of `rows` rows.
template <class F>
void in_chunks(std::size_t rows, F f) {
  for (std::size_t from = 0; from < rows; from += kRowsPerChunk) f(from, std::min(kRowsPerChunk, rows - from));
}

// ---------------------------------------------------------------------------------------------
// Rank 0

class SpreadTetgenWrite {
 public:
  SpreadTetgenWrite(const SpreadMesh& mesh, const MeshOutput& output, int exponent)
      : mesh_(mesh), output_(output), exponent_(exponent) {
    MPI_Comm_size(job_comm(), &size_);
  }

  void run(OutputSet& set, const std::string& prefix) {
    // 1. Each rank names the bulks it keeps and their rows' fingerprints.
    const std::string placement = serialize_placement(mesh_.bulks);  // before the order: no rank waits for it
    broadcast_text(std::string(kSpreadTetgenOrder) + '\n' + std::to_string(exponent_));
    broadcast_text(placement);
    try {
      take_claims();
      // 2. The set's ID, from every run of rows in row order.
      const std::string id = set_id();
      // 3. The files, each run of rows in row order: rank 0's own formatted here, the others'
      //    streamed from the ranks keeping them.
      for (TetgenFile file : {TetgenFile::node, TetgenFile::ele, TetgenFile::face, TetgenFile::neigh}) {
        const std::string final_path = prefix + extension(file);
        set.add(final_path, [&](const std::string& temporary) { write_file(file, id, temporary, final_path); });
      }
    } catch (...) {
      end();
      throw;
    }
    end();
  }

 private:
  // A run of rows: a bulk's, or (bulk null) rank 0's own points (the split surface's, then those
  // healing added) or the band's tets.
  struct RowRun {
    std::int64_t first = 0, count = 0;
    const SpreadBulk* bulk = nullptr;
  };

  struct Claim {
    int rank = 0;
    RowsFingerprint points, tets;
  };

  void end() {
    for (int rank = 1; rank < size_; ++rank) send_to(rank, "", kWorkerSeconds);
  }

  void take_claims() {
    std::exception_ptr failure;
    for (int rank = 1; rank < size_; ++rank) {
      const auto values = values_of<std::uint64_t>(receive_from(rank, kWorkerSeconds));
      if (!values || values->size() % 5 != 0) {
        failure = std::make_exception_ptr(InternalError("rank " + std::to_string(rank) + " named its bulks wrongly"));
        continue;
      }
      for (std::size_t i = 0; i < values->size(); i += 5) {
        const auto piece = static_cast<int>((*values)[i]);
        const SpreadBulk* bulk = bulk_of(piece);
        if (!bulk || bulk->here || claims_.count(piece))
          failure = std::make_exception_ptr(
              InternalError("rank " + std::to_string(rank) + " claims the bulk of piece " + std::to_string(piece)));
        claims_[piece] = {rank, {(*values)[i + 1], (*values)[i + 2]}, {(*values)[i + 3], (*values)[i + 4]}};
      }
    }
    if (failure) std::rethrow_exception(failure);
    for (const SpreadBulk& bulk : mesh_.bulks)
      if (!bulk.here && !claims_.count(bulk.piece))
        throw InternalError("no rank keeps the bulk of piece " + std::to_string(bulk.piece));
  }

  const SpreadBulk* bulk_of(int piece) const {
    for (const SpreadBulk& bulk : mesh_.bulks)
      if (bulk.piece == piece) return &bulk;
    return nullptr;
  }

  // The runs of a file's rows in row order (.face: none, rank 0 keeps the boundary whole).
  // Throws InternalError when they do not tile the mesh's rows.
  std::vector<RowRun> runs_of(TetgenFile file) const {
    std::vector<RowRun> runs;
    const bool points = file == TetgenFile::node;
    if (points) {
      runs.push_back({0, static_cast<std::int64_t>(mesh_.split_points.size()), nullptr});
      runs.push_back({mesh_.first_healing_point, static_cast<std::int64_t>(mesh_.healing_points.size()), nullptr});
    } else {
      runs.push_back({mesh_.first_band_tet, static_cast<std::int64_t>(mesh_.band_tets.size()), nullptr});
    }
    for (const SpreadBulk& bulk : mesh_.bulks)
      runs.push_back(points ? RowRun{bulk.first_point, bulk.points, &bulk} : RowRun{bulk.first_tet, bulk.tets, &bulk});
    runs.erase(std::remove_if(runs.begin(), runs.end(), [](const RowRun& r) { return r.count == 0; }), runs.end());
    std::sort(runs.begin(), runs.end(), [](const RowRun& a, const RowRun& b) { return a.first < b.first; });
    std::int64_t next = 0;
    for (const RowRun& run : runs) {
      if (run.first != next) throw InternalError("the spread mesh's rows do not follow one another");
      next += run.count;
    }
    if (next != (points ? mesh_.points : mesh_.tets)) throw InternalError("the spread mesh's rows are not all kept");
    return runs;
  }

  // Rank 0's own rows of a run, packed (.node and .ele).
  const char* own_rows(TetgenFile file, const RowRun& run) const {
    const auto bytes = [](const auto& rows) { return reinterpret_cast<const char*>(rows.data()); };
    if (file == TetgenFile::ele) return bytes(run.bulk ? run.bulk->block.tets : mesh_.band_tets);
    if (run.bulk) return bytes(run.bulk->block.steiner_points);
    return bytes(run.first == 0 ? mesh_.split_points : mesh_.healing_points);
  }

  std::string set_id() const {
    RowsFingerprint points, tets;
    for (const RowRun& run : runs_of(TetgenFile::node))
      points = combine(points, run.bulk && !run.bulk->here
                                   ? claims_.at(run.bulk->piece).points
                                   : fingerprint_rows(TetgenFile::node, own_rows(TetgenFile::node, run),
                                                      static_cast<std::size_t>(run.count)));
    for (const RowRun& run : runs_of(TetgenFile::ele))
      tets =
          combine(tets, run.bulk && !run.bulk->here ? claims_.at(run.bulk->piece).tets
                                                    : fingerprint_rows(TetgenFile::ele, own_rows(TetgenFile::ele, run),
                                                                       static_cast<std::size_t>(run.count)));
    const auto& faces = output_.boundary;
    return mesh_id(points, tets,
                   fingerprint_rows(TetgenFile::face, reinterpret_cast<const char*>(faces.data()), faces.size()));
  }

  void write_file(TetgenFile file, const std::string& id, const std::string& path, const std::string& shown) {
    const bool faces = file == TetgenFile::face;
    const std::size_t count = faces                      ? output_.boundary.size()
                              : file == TetgenFile::node ? static_cast<std::size_t>(mesh_.points)
                                                         : static_cast<std::size_t>(mesh_.tets);
    write_tetgen_file(
        file, count, id, path, shown,
        [&](BufferedFile& out) {
          if (faces) {
            const auto* rows = reinterpret_cast<const char*>(output_.boundary.data());
            return write_tetgen_lines(out, file, rows, 0, count, output_.split_from);
          }
          write_runs(out, file, runs_of(file));
        },
        Closing::in_background);
  }

  // Orders every rank keeping some of the runs to format them all, then writes the runs in row
  // order: rank 0's own formatted here, the others' as their chunks come. After a failure (a full
  // disk, a rank that cannot format its run) it still takes every chunk ordered, so no rank is
  // left waiting, then throws the first failure.
  void write_runs(BufferedFile& out, TetgenFile file, const std::vector<RowRun>& runs) const {
    send_file_orders(file, runs);
    std::exception_ptr failure;
    for (const RowRun& run : runs) {
      if (run.bulk && !run.bulk->here) {
        take_text_chunks(out, claims_.at(run.bulk->piece).rank, failure);
        continue;
      }
      if (failure) continue;
      try {
        write_own_run(out, file, run);
      } catch (...) {
        failure = std::current_exception();
      }
    }
    if (failure) std::rethrow_exception(failure);
  }

  void send_file_orders(TetgenFile file, const std::vector<RowRun>& runs) const {
    std::map<int, std::vector<const SpreadBulk*>> by_rank;
    for (const RowRun& run : runs)
      if (run.bulk && !run.bulk->here) by_rank[claims_.at(run.bulk->piece).rank].push_back(run.bulk);
    for (const auto& [rank, bulks] : by_rank) {
      std::vector<std::int32_t> pieces;
      for (const SpreadBulk* bulk : bulks) pieces.push_back(bulk->piece);
      send_to(rank, file_order(file, pieces), kWorkerSeconds);
      if (file == TetgenFile::neigh)
        for (const SpreadBulk* bulk : bulks) send_to(rank, bytes_of(run_of(bulk->across)), kWorkerSeconds);
    }
  }

  void write_own_run(BufferedFile& out, TetgenFile file, const RowRun& run) const {
    const auto count = static_cast<std::size_t>(run.count), first = static_cast<std::size_t>(run.first);
    if (file != TetgenFile::neigh) return write_tetgen_lines(out, file, own_rows(file, run), first, count);
    in_chunks(count, [&](std::size_t from, std::size_t n) {
      const std::vector<Tet> rows =
          run.bulk ? neighbour_rows(run.bulk->block.neighbours, run.bulk->first_tet, run.bulk->across, from, n)
                   : neighbour_rows(mesh_.band_neighbours, mesh_.first_band_tet, mesh_.band_across, from, n);
      write_tetgen_lines(out, file, reinterpret_cast<const char*>(rows.data()), first + from, n);
    });
  }

  const SpreadMesh& mesh_;
  const MeshOutput& output_;
  int exponent_ = 0;
  int size_ = 1;
  std::map<int, Claim> claims_;  // by piece: the bulks kept elsewhere
};

// ---------------------------------------------------------------------------------------------
// The other ranks

struct OwnBulk {
  const TetBlock* block = nullptr;
  SpreadBulk place;
};

// The bulks this rank keeps, checked against their placement, and what it tells rank 0 of them.
std::map<int, OwnBulk> own_bulks(const std::string& placement, std::map<int, TetBlock>& bulks,
                                 std::vector<std::uint64_t>& claims) {
  std::map<int, OwnBulk> own;
  for (SpreadBulk& place : deserialize_placement(placement)) {
    const auto bulk = bulks.find(place.piece);
    if (bulk == bulks.end()) continue;
    const TetBlock& block = bulk->second;
    if (static_cast<std::int64_t>(block.steiner_points.size()) != place.points ||
        static_cast<std::int64_t>(block.tets.size()) != place.tets || block.neighbours.size() != block.tets.size())
      throw InternalError("the bulk of piece " + std::to_string(place.piece) + " does not match its placement");
    const RowsFingerprint points = fingerprint_rows(
        TetgenFile::node, reinterpret_cast<const char*>(block.steiner_points.data()), block.steiner_points.size());
    const RowsFingerprint tets =
        fingerprint_rows(TetgenFile::ele, reinterpret_cast<const char*>(block.tets.data()), block.tets.size());
    claims.insert(claims.end(),
                  {static_cast<std::uint64_t>(place.piece), points.hash, points.words, tets.hash, tets.words});
    own[place.piece] = {&block, std::move(place)};
  }
  return own;
}

// The chunks of one file's runs this rank keeps, in order: per run "T" + its lines, a chunk at a
// time ("E" + why not, when it cannot), then "" after the run.
class RunChunks {
 public:
  RunChunks(TetgenFile file, std::vector<std::int32_t> pieces,
            std::vector<std::optional<std::vector<FaceAcross>>> across, const std::map<int, OwnBulk>& own)
      : file_(file), pieces_(std::move(pieces)), across_(std::move(across)), own_(own) {}

  bool done() const { return run_ == pieces_.size(); }

  std::string next() {
    if (ended_) {  // the run's end
      ended_ = false, from_ = 0, ++run_;
      return "";
    }
    std::string chunk = "T";
    try {
      const OwnBulk& bulk = bulk_of(pieces_[run_]);
      const std::size_t rows = file_ == TetgenFile::node ? bulk.block->steiner_points.size() : bulk.block->tets.size();
      const std::size_t n = std::min(kRowsPerChunk, rows - from_);
      append_lines(chunk, bulk, n);
      from_ += n;
      ended_ = from_ == rows;
    } catch (const std::exception& e) {
      chunk = std::string("E") + e.what();
      ended_ = true;
    }
    return chunk;
  }

 private:
  const OwnBulk& bulk_of(std::int32_t piece) const {
    const auto found = own_.find(piece);
    if (found == own_.end())
      throw InternalError("rank " + std::to_string(my_rank()) + " keeps no bulk of piece " + std::to_string(piece));
    return found->second;
  }

  void append_lines(std::string& chunk, const OwnBulk& bulk, std::size_t n) const {
    const TetBlock& block = *bulk.block;
    const SpreadBulk& place = bulk.place;
    const auto bytes = [](const auto& rows) { return reinterpret_cast<const char*>(rows.data()); };
    if (file_ == TetgenFile::node)
      return append_tetgen_lines(chunk, file_, bytes(block.steiner_points) + from_ * sizeof(Point3),
                                 static_cast<std::size_t>(place.first_point) + from_, n, SIZE_MAX);
    if (file_ == TetgenFile::ele)
      return append_tetgen_lines(chunk, file_, bytes(block.tets) + from_ * sizeof(Tet),
                                 static_cast<std::size_t>(place.first_tet) + from_, n, SIZE_MAX);
    if (file_ != TetgenFile::neigh)
      throw InternalError("rank " + std::to_string(my_rank()) + " was asked for rows it does not keep");
    if (!across_[run_] || test_hooks::block_lost(my_rank()))
      throw OutputError("rank " + std::to_string(my_rank()) + " did not receive the faces its bulk of piece " +
                        std::to_string(place.piece) + " shares with the rest of the mesh");
    const std::vector<Tet> rows = neighbour_rows(block.neighbours, place.first_tet, *across_[run_], from_, n);
    append_tetgen_lines(chunk, file_, bytes(rows), static_cast<std::size_t>(place.first_tet) + from_, n, SIZE_MAX);
  }

  TetgenFile file_;
  std::vector<std::int32_t> pieces_;
  std::vector<std::optional<std::vector<FaceAcross>>> across_;
  const std::map<int, OwnBulk>& own_;
  std::size_t run_ = 0, from_ = 0;
  bool ended_ = false;
};

// Answers one file's order: formats up to kReadAheadBytes ahead, then sends chunk after chunk,
// formatting the next while rank 0 writes the last.
void answer_file_order(const std::string& order, const std::map<int, OwnBulk>& own) {
  const auto file = static_cast<TetgenFile>(order.size() > 1 ? order[1] - '0' : -1);
  std::vector<std::int32_t> pieces = values_of<std::int32_t>(order, 2).value_or(std::vector<std::int32_t>{});
  std::vector<std::optional<std::vector<FaceAcross>>> across(pieces.size());
  if (file == TetgenFile::neigh)
    for (auto& faces : across) faces = values_of<FaceAcross>(receive_from(0, kRootSeconds));
  RunChunks chunks(file, std::move(pieces), std::move(across), own);
  std::deque<std::string> ready;
  std::size_t ready_bytes = 0;
  const auto format_next = [&] {
    ready.push_back(chunks.next());
    ready_bytes += ready.back().size();
  };
  while (!chunks.done() && ready_bytes < kReadAheadBytes) format_next();
  while (!ready.empty()) {
    send_to(0, ready.front(), kRootSeconds);
    ready_bytes -= ready.front().size();
    ready.pop_front();
    if (!chunks.done()) format_next();
  }
}

}  // namespace

void add_spread_tetgen_files(OutputSet& set, const SpreadMesh& mesh, const MeshOutput& output,
                             const std::string& prefix, int exponent) {
  SpreadTetgenWrite(mesh, output, exponent).run(set, prefix);
}

void stream_own_tetgen_rows(std::istringstream& order, BulksForWrites& kept) {
  std::string exponent;
  std::getline(order, exponent);
  const std::string placement = broadcast_text("");
  // 1. The bulks this rank keeps and their fingerprints (none when it cannot say: rank 0 then
  //    finds bulks nobody keeps and fails the write).
  std::map<int, OwnBulk> own;
  std::vector<std::uint64_t> claims;
  try {
    own = own_bulks(placement, kept.get(std::stoi(exponent)), claims);
  } catch (const std::exception& e) {
    log::error(e.what());
    own.clear(), claims.clear();
  }
  send_to(0, bytes_of(run_of(claims)), kRootSeconds);
  // 2. The runs of rows rank 0 orders, file by file, until it says the files are done.
  for (std::string order = receive_from(0, kRootSeconds); !order.empty(); order = receive_from(0, kRootSeconds))
    answer_file_order(order, own);
}

}  // namespace partet::mpi
