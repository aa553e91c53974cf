#include "mpi/spread_row_files.hpp"

#include <algorithm>
#include <cstring>
#include <deque>
#include <exception>
#include <map>
#include <vector>

#include "common/log.hpp"
#include "common/test_hooks.hpp"
#include "io/buffered_file.hpp"
#include "io/row_lines.hpp"
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
// A claim: the piece, the fingerprints of the points and tets (2 words each), the bounds (6 doubles).
constexpr std::size_t kClaimWords = 11;

// A section's order to one rank: "F", the kind of rows, the number of row 0, then the pieces of
// its runs (int32 each), in row order.
struct SectionOrder {
  RowLines lines = RowLines::tetgen_node;
  std::int64_t number_from = 0;
  std::vector<std::int32_t> pieces;
  static constexpr std::size_t kHead = 2 + sizeof(std::int64_t);

  std::string bytes() const {
    std::string order = "F";
    order += static_cast<char>(lines);
    order.append(reinterpret_cast<const char*>(&number_from), sizeof number_from);
    order.append(bytes_of(run_of(pieces)));
    return order;
  }
  // False when the bytes are no such order (an unknown kind of rows is read, and fails to format).
  bool read(const std::string& order) {
    if (order.size() < kHead || order[0] != 'F') return false;
    lines = static_cast<RowLines>(order[1]);
    std::memcpy(&number_from, order.data() + 2, sizeof number_from);
    auto values = values_of<std::int32_t>(order, kHead);
    if (values) pieces = std::move(*values);
    return values.has_value();
  }
};

// Calls f(from, count) for each chunk of `rows` rows.
template <class F>
void in_chunks(std::size_t rows, F f) {
  for (std::size_t from = 0; from < rows; from += kRowsPerChunk) f(from, std::min(kRowsPerChunk, rows - from));
}

// ---------------------------------------------------------------------------------------------
// Rank 0

class SpreadRowsWrite {
 public:
  SpreadRowsWrite(MeshFormat format, const SpreadMesh& mesh, const MeshOutput& output, int exponent)
      : format_(format), mesh_(mesh), output_(output), exponent_(exponent) {
    MPI_Comm_size(job_comm(), &size_);
  }

  void run(OutputSet& set, const std::string& prefix) {
    // 1. Each rank names the bulks it keeps, with their rows' fingerprints and bounds.
    const std::string placement = serialize_placement(mesh_.bulks);  // before the order: no rank waits for it
    broadcast_text(std::string(kSpreadRowsOrder) + '\n' + std::to_string(exponent_) + '\n' + mesh_format_name(format_));
    broadcast_text(placement);
    try {
      take_claims();
      // 2. The files, each section's runs of rows in row order: rank 0's own formatted here, the
      //    others' streamed from the ranks keeping them.
      format_ == MeshFormat::tetgen ? add_tetgen_files(set, prefix) : add_single_file(set, prefix);
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
    Bounds box;
  };

  void end() {
    for (int rank = 1; rank < size_; ++rank) send_to(rank, "", kWorkerSeconds);
  }

  void take_claims() {
    std::exception_ptr failure;
    for (int rank = 1; rank < size_; ++rank) {
      const auto values = values_of<std::uint64_t>(receive_from(rank, kWorkerSeconds));
      if (!values || values->size() % kClaimWords != 0) {
        failure = std::make_exception_ptr(InternalError("rank " + std::to_string(rank) + " named its bulks wrongly"));
        continue;
      }
      for (std::size_t i = 0; i < values->size(); i += kClaimWords) {
        const std::uint64_t* v = values->data() + i;
        const auto piece = static_cast<int>(v[0]);
        const SpreadBulk* bulk = bulk_of(piece);
        if (!bulk || bulk->here || claims_.count(piece))
          failure = std::make_exception_ptr(
              InternalError("rank " + std::to_string(rank) + " claims the bulk of piece " + std::to_string(piece)));
        Claim& claim = claims_[piece];
        claim = {rank, {v[1], v[2]}, {v[3], v[4]}, {}};
        std::memcpy(claim.box.min.data(), v + 5, sizeof claim.box.min);
        std::memcpy(claim.box.max.data(), v + 8, sizeof claim.box.max);
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

  void add_tetgen_files(OutputSet& set, const std::string& prefix) {
    if (!mesh_.has_across) throw InternalError("the spread mesh kept no faces across its parts for the .neigh file");
    const std::string id =
        mesh_id(fingerprint(true), fingerprint(false), fingerprint_rows(TetgenFile::face, output_.boundary));
    for (TetgenFile file : {TetgenFile::node, TetgenFile::ele, TetgenFile::face, TetgenFile::neigh}) {
      const std::string shown = prefix + extension(file);
      const bool faces = file == TetgenFile::face;
      const std::size_t count = faces ? output_.boundary.size()
                                      : static_cast<std::size_t>(file == TetgenFile::node ? mesh_.points : mesh_.tets);
      const RowLines lines = file == TetgenFile::node  ? RowLines::tetgen_node
                             : file == TetgenFile::ele ? RowLines::tetgen_ele
                                                       : RowLines::tetgen_neigh;
      set.add(shown, [&](const std::string& temporary) {
        write_tetgen_file(
            file, count, id, temporary, shown,
            [&](BufferedFile& out) {
              if (!faces) return write_runs(out, lines, 0);
              write_tetgen_lines(out, file, bytes_of(run_of(output_.boundary)).data(), 0, count, output_.split_from);
            },
            Closing::in_background);
      });
    }
  }

  void add_single_file(OutputSet& set, const std::string& prefix) {
    const std::string shown = format_paths(format_, prefix).front();
    if (format_ == MeshFormat::vtu) {
      VtuRows rows;
      rows.points = static_cast<std::uint64_t>(mesh_.points), rows.tets = static_cast<std::uint64_t>(mesh_.tets);
      rows.write = [this](ByteSink& out, RowLines lines) { write_runs(out, lines, 0); };
      return set.add(shown, [&](const std::string& temporary) { write_vtu(rows, temporary, shown); });
    }
    MeshRows rows;
    rows.points = static_cast<std::uint64_t>(mesh_.points), rows.tets = static_cast<std::uint64_t>(mesh_.tets);
    if (format_ != MeshFormat::medit) rows.box = box();
    rows.write = [this](BufferedFile& out, RowLines lines, std::int64_t number_from) {
      write_runs(out, lines, number_from);
    };
    set.add(shown, [&](const std::string& temporary) {
      if (format_ == MeshFormat::medit)
        return write_medit(rows, output_.boundary, output_.split_from, temporary, shown);
      write_msh(rows, output_.boundary, output_.split_from, temporary, shown, format_ == MeshFormat::msh_binary);
    });
  }

  // The runs of the point or tet rows in row order. Throws InternalError when they do not tile
  // the mesh's rows.
  std::vector<RowRun> runs_of(bool points) const {
    std::vector<RowRun> runs;
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

  bool elsewhere(const RowRun& run) const { return run.bulk && !run.bulk->here; }

  // Rank 0's own rows of a run.
  const std::vector<Point3>& own_points(const RowRun& run) const {
    if (run.bulk) return run.bulk->block.steiner_points;
    return run.first == 0 ? mesh_.split_points : mesh_.healing_points;
  }
  const std::vector<Tet>& own_tets(const RowRun& run) const {
    return run.bulk ? run.bulk->block.tets : mesh_.band_tets;
  }

  // The fingerprint of all point (or tet) rows, from every run in row order.
  RowsFingerprint fingerprint(bool points) const {
    RowsFingerprint all;
    for (const RowRun& run : runs_of(points)) {
      if (elsewhere(run)) {
        const Claim& claim = claims_.at(run.bulk->piece);
        all = combine(all, points ? claim.points : claim.tets);
      } else {
        all = combine(all, points ? fingerprint_rows(TetgenFile::node, own_points(run))
                                  : fingerprint_rows(TetgenFile::ele, own_tets(run)));
      }
    }
    return all;
  }

  Bounds box() const {
    return bounds_of_rows(mesh_, [this](const SpreadBulk& bulk) { return claims_.at(bulk.piece).box; });
  }

  // Orders every rank keeping some of the runs to format them all, then writes the runs in row
  // order: rank 0's own formatted here, the others' as their chunks come. After a failure (a full
  // disk, a rank that cannot format its run) it still takes every chunk ordered, so no rank is
  // left waiting, then throws the first failure. Into a file, or a sink (a .vtu file's array).
  template <class Out>
  void write_runs(Out& out, RowLines lines, std::int64_t number_from) const {
    const std::vector<RowRun> runs = runs_of(formats_points(lines));
    send_section_orders(lines, number_from, runs);
    std::exception_ptr failure;
    for (const RowRun& run : runs) {
      if (elsewhere(run)) {
        take_text_chunks(out, claims_.at(run.bulk->piece).rank, failure);
        continue;
      }
      if (failure) continue;
      try {
        write_own_run(out, lines, number_from, run);
      } catch (...) {
        failure = std::current_exception();
      }
    }
    if (failure) std::rethrow_exception(failure);
  }

  void send_section_orders(RowLines lines, std::int64_t number_from, const std::vector<RowRun>& runs) const {
    std::map<int, std::vector<const SpreadBulk*>> by_rank;
    for (const RowRun& run : runs)
      if (elsewhere(run)) by_rank[claims_.at(run.bulk->piece).rank].push_back(run.bulk);
    for (const auto& [rank, bulks] : by_rank) {
      SectionOrder order{lines, number_from, {}};
      for (const SpreadBulk* bulk : bulks) order.pieces.push_back(bulk->piece);
      send_to(rank, order.bytes(), kWorkerSeconds);
      if (lines == RowLines::tetgen_neigh)
        for (const SpreadBulk* bulk : bulks) send_to(rank, bytes_of(run_of(bulk->across)), kWorkerSeconds);
    }
  }

  template <class Out>
  void write_own_run(Out& out, RowLines lines, std::int64_t number_from, const RowRun& run) const {
    const auto count = static_cast<std::size_t>(run.count);
    if (formats_points(lines))
      return write_row_lines(out, lines, {own_points(run).data(), count, run.first, number_from});
    if (lines == RowLines::tetgen_neigh) {
      return in_chunks(count, [&](std::size_t from, std::size_t n) {
        const std::vector<Tet> rows =
            run.bulk ? neighbour_rows(run.bulk->block.neighbours, run.bulk->first_tet, run.bulk->across, from, n)
                     : neighbour_rows(mesh_.band_neighbours, mesh_.first_band_tet, mesh_.band_across, from, n);
        write_row_lines(out, lines, {rows.data(), n, run.first + static_cast<std::int64_t>(from), number_from});
      });
    }
    std::vector<std::int32_t> solid, piece;
    const bool columns = lines == RowLines::medit_tet || lines == RowLines::vtu_region || lines == RowLines::vtu_piece;
    if (columns && run.bulk) bulk_columns(run.bulk->block, *run.bulk, solid, piece);
    const std::int32_t* region = run.bulk ? solid.data() : mesh_.band_solid.data();
    const std::int32_t* pieces = run.bulk ? piece.data() : mesh_.band_piece.data();
    write_row_lines(out, lines, {own_tets(run).data(), count, run.first, number_from, region, pieces});
  }

  MeshFormat format_;
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
  std::vector<std::int32_t> solid, piece;  // per tet, for MEDIT's references and a .vtu file's cell data
};

// What a rank tells rank 0 of a bulk it keeps: what the format needs (the fingerprints for
// TetGen's ID, the bounds for MSH's box).
void add_claim(MeshFormat format, const OwnBulk& bulk, std::vector<std::uint64_t>& claims) {
  const TetBlock& block = *bulk.block;
  RowsFingerprint points, tets;
  if (format == MeshFormat::tetgen)
    points = fingerprint_rows(TetgenFile::node, block.steiner_points),
    tets = fingerprint_rows(TetgenFile::ele, block.tets);
  Bounds box;
  if (format == MeshFormat::msh || format == MeshFormat::msh_binary) box = bounds_of(block.steiner_points);
  std::uint64_t words[kClaimWords] = {static_cast<std::uint64_t>(bulk.place.piece), points.hash, points.words,
                                      tets.hash, tets.words};
  std::memcpy(words + 5, box.min.data(), sizeof box.min);
  std::memcpy(words + 8, box.max.data(), sizeof box.max);
  claims.insert(claims.end(), std::begin(words), std::end(words));
}

// The bulks this rank keeps, checked against their placement, and what it tells rank 0 of them.
std::map<int, OwnBulk> own_bulks(MeshFormat format, const std::string& placement, std::map<int, TetBlock>& bulks,
                                 std::vector<std::uint64_t>& claims) {
  std::map<int, OwnBulk> own;
  for (SpreadBulk& place : deserialize_placement(placement)) {
    const auto bulk = bulks.find(place.piece);
    if (bulk == bulks.end()) continue;
    const TetBlock& block = bulk->second;
    if (static_cast<std::int64_t>(block.steiner_points.size()) != place.points ||
        static_cast<std::int64_t>(block.tets.size()) != place.tets || block.neighbours.size() != block.tets.size())
      throw InternalError("the bulk of piece " + std::to_string(place.piece) + " does not match its placement");
    OwnBulk& kept = own[place.piece];
    kept = {&block, std::move(place), {}};
    if (format == MeshFormat::medit || format == MeshFormat::vtu)
      bulk_columns(block, kept.place, kept.solid, kept.piece);
    add_claim(format, kept, claims);
  }
  return own;
}

// The chunks of one section's runs this rank keeps, in order: per run "T" + its text, a chunk at
// a time ("E" + why not, when it cannot), then "" after the run.
class RunChunks {
 public:
  RunChunks(SectionOrder order, std::vector<std::optional<std::vector<FaceAcross>>> across,
            const std::map<int, OwnBulk>& own)
      : order_(std::move(order)), across_(std::move(across)), own_(own) {}

  bool done() const { return run_ == order_.pieces.size(); }

  std::string next() {
    if (ended_) {  // the run's end
      ended_ = false, from_ = 0, ++run_;
      return "";
    }
    std::string chunk = "T";
    try {
      const OwnBulk& bulk = bulk_of(order_.pieces[run_]);
      const std::size_t rows =
          formats_points(order_.lines) ? bulk.block->steiner_points.size() : bulk.block->tets.size();
      const std::size_t n = std::min(kRowsPerChunk, rows - from_);
      append_text(chunk, bulk, n);
      from_ += n;
      ended_ = from_ == rows;
    } catch (const std::exception&) {
      chunk = "E" + error_message(std::current_exception(), my_rank());
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

  void append_text(std::string& chunk, const OwnBulk& bulk, std::size_t n) const {
    test_hooks::write_out_of_memory(my_rank());
    const TetBlock& block = *bulk.block;
    const SpreadBulk& place = bulk.place;
    const auto from = static_cast<std::int64_t>(from_);
    if (formats_points(order_.lines))
      return append_row_lines(chunk, order_.lines,
                              {block.steiner_points.data() + from_, n, place.first_point + from, order_.number_from});
    RowsToFormat rows{block.tets.data() + from_, n, place.first_tet + from, order_.number_from};
    std::vector<Tet> neighbours;
    if (order_.lines == RowLines::tetgen_neigh) {
      if (!across_[run_] || test_hooks::block_lost(my_rank()))
        throw OutputError("rank " + std::to_string(my_rank()) + " did not receive the faces its bulk of piece " +
                          std::to_string(place.piece) + " shares with the rest of the mesh");
      neighbours = neighbour_rows(block.neighbours, place.first_tet, *across_[run_], from_, n);
      rows.data = neighbours.data();
    }
    if (order_.lines == RowLines::medit_tet || order_.lines == RowLines::vtu_region ||
        order_.lines == RowLines::vtu_piece) {
      if (bulk.solid.size() != block.tets.size() || bulk.piece.size() != block.tets.size())
        throw InternalError("rank " + std::to_string(my_rank()) + " has no cell data for the bulk of piece " +
                            std::to_string(place.piece));
      rows.region = bulk.solid.data() + from_, rows.piece = bulk.piece.data() + from_;
    }
    append_row_lines(chunk, order_.lines, rows);
  }

  SectionOrder order_;
  std::vector<std::optional<std::vector<FaceAcross>>> across_;
  const std::map<int, OwnBulk>& own_;
  std::size_t run_ = 0, from_ = 0;
  bool ended_ = false;
};

// Answers one section's order: formats up to kReadAheadBytes ahead, then sends chunk after chunk,
// formatting the next while rank 0 writes the last.
void answer_section_order(const std::string& bytes, const std::map<int, OwnBulk>& own) {
  SectionOrder order;
  if (!order.read(bytes)) order = {};  // no runs: rank 0 finds none of the text it ordered
  std::vector<std::optional<std::vector<FaceAcross>>> across(order.pieces.size());
  if (order.lines == RowLines::tetgen_neigh)
    for (auto& faces : across) faces = values_of<FaceAcross>(receive_from(0, kRootSeconds));
  RunChunks chunks(std::move(order), std::move(across), own);
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

void add_spread_row_files(OutputSet& set, MeshFormat format, const SpreadMesh& mesh, const MeshOutput& output,
                          const std::string& prefix, int exponent) {
  SpreadRowsWrite(format, mesh, output, exponent).run(set, prefix);
}

void stream_own_rows(std::istringstream& order, BulksForWrites& kept) {
  std::string exponent, format_name;
  std::getline(order, exponent), std::getline(order, format_name);
  const std::string placement = broadcast_text("");
  // 1. The bulks this rank keeps and what rank 0 needs of them (none when it cannot say: rank 0
  //    then finds bulks nobody keeps and fails the write).
  std::map<int, OwnBulk> own;
  std::vector<std::uint64_t> claims;
  try {
    own = own_bulks(mesh_format(format_name), placement, kept.get(std::stoi(exponent)), claims);
  } catch (const std::exception& e) {
    log::error(e.what());
    own.clear(), claims.clear();
  }
  send_to(0, bytes_of(run_of(claims)), kRootSeconds);
  // 2. The runs of rows rank 0 orders, section by section, until it says the files are done.
  for (std::string order = receive_from(0, kRootSeconds); !order.empty(); order = receive_from(0, kRootSeconds))
    answer_section_order(order, own);
}

}  // namespace partet::mpi
