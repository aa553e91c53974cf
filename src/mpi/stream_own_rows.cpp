// A worker's side of the single files of a spread mesh (spread_row_files.hpp): the rows of the
// bulks it keeps, formatted as rank 0 orders them, section by section, and sent in chunks.
#include "mpi/spread_row_files.hpp"

#include <algorithm>
#include <cstring>
#include <exception>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/log.hpp"
#include "common/test_hooks.hpp"
#include "io/buffered_file.hpp"
#include "io/row_lines.hpp"
#include "io/tetgen_files.hpp"
#include "mpi/spread_row_order.hpp"
#include "mpi/transport.hpp"
#include "mpi/write_messages.hpp"
#include "partet/errors.hpp"
#include "runner/serialize.hpp"

namespace partet::mpi {
namespace {

// Text a rank formats ahead of rank 0, while rank 0 writes the runs before its own: its runs are
// then formatted while rank 0 formats its own, not after.
constexpr std::size_t kReadAheadBytes = std::size_t{256} << 20;

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
    tets = fingerprint_tets(block.tets, block.ids);
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
    kept = {&block, std::move(place), {}, {}};
    if (format == MeshFormat::medit || format == MeshFormat::vtu)
      bulk_columns(block, kept.place, kept.solid, kept.piece);
    add_claim(format, kept, claims);
  }
  return own;
}

// Rank 0's points this rank formats for it (kGivenPoints): the number of the first row, and the
// rows as they came (formatted from there: no copy).
struct GivenPoints {
  std::int64_t first = 0;
  std::string rows;
  std::size_t count() const { return rows.size() / sizeof(Point3); }
};

// The run after a kGivenPoints in the order (both messages are taken whatever they hold); nothing
// when they are no such run.
std::optional<GivenPoints> receive_given_points() {
  const auto first = values_of<std::int64_t>(receive_from(0, kRootSeconds));
  GivenPoints given;
  given.rows = receive_from(0, kRootSeconds);
  if (!first || first->size() != 1 || given.rows.size() % sizeof(Point3) != 0 || test_hooks::points_lost(my_rank()))
    return std::nullopt;
  given.first = first->front();
  return given;
}

// The chunks of one section's runs this rank formats, in order: per run "T" + its text, a chunk at
// a time ("E" + why not, when it cannot), then "" after the run.
class RunChunks {
 public:
  RunChunks(SectionOrder order, std::vector<std::optional<std::vector<FaceAcross>>> across,
            std::vector<std::optional<GivenPoints>> given, const std::map<int, OwnBulk>& own)
      : order_(std::move(order)), across_(std::move(across)), given_(std::move(given)), own_(own) {}

  bool done() const { return run_ == order_.pieces.size(); }

  std::string next() {
    if (ended_) {  // the run's end
      ended_ = false, from_ = 0, ++run_;
      return "";
    }
    std::string chunk = "T";
    try {
      const std::size_t rows = rows_of_run();
      const std::size_t n = std::min(kRowsPerChunk, rows - from_);
      test_hooks::write_out_of_memory(my_rank());
      if (order_.pieces[run_] == kGivenPoints)
        append_given_text(chunk, n);
      else
        append_text(chunk, bulk_of(order_.pieces[run_]), n);
      from_ += n;
      ended_ = from_ == rows;
    } catch (const std::exception&) {
      chunk = "E" + error_message(std::current_exception(), my_rank());
      ended_ = true;
    }
    return chunk;
  }

 private:
  std::size_t rows_of_run() const {
    if (order_.pieces[run_] == kGivenPoints) return given().count();
    const TetBlock& block = *bulk_of(order_.pieces[run_]).block;
    return formats_points(order_.lines) ? block.steiner_points.size() : block.tets.size();
  }

  const GivenPoints& given() const {
    if (!given_[run_])
      throw OutputError("rank " + std::to_string(my_rank()) +
                        " did not receive its share of the input's points to format");
    return *given_[run_];
  }

  void append_given_text(std::string& chunk, std::size_t n) const {
    if (!formats_points(order_.lines))
      throw InternalError("rank " + std::to_string(my_rank()) + " was given points to format as other rows");
    const GivenPoints& points = given();
    append_row_lines(chunk, order_.lines,
                     {points.rows.data() + from_ * sizeof(Point3), n, points.first + static_cast<std::int64_t>(from_),
                      order_.number_from});
  }

  const OwnBulk& bulk_of(std::int32_t piece) const {
    const auto found = own_.find(piece);
    if (found == own_.end())
      throw InternalError("rank " + std::to_string(my_rank()) + " keeps no bulk of piece " + std::to_string(piece));
    return found->second;
  }

  void append_text(std::string& chunk, const OwnBulk& bulk, std::size_t n) const {
    const TetBlock& block = *bulk.block;
    const SpreadBulk& place = bulk.place;
    const auto from = static_cast<std::int64_t>(from_);
    if (formats_points(order_.lines))
      return append_row_lines(chunk, order_.lines,
                              {block.steiner_points.data() + from_, n, place.first_point + from, order_.number_from});
    RowsToFormat rows{block.tets.data() + from_, n, place.first_tet + from, order_.number_from};
    rows.ids = block.ids;
    std::vector<NeighbourRow> neighbours;
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
  std::vector<std::optional<GivenPoints>> given_;  // per run: rank 0's points (kGivenPoints)
  const std::map<int, OwnBulk>& own_;
  std::size_t run_ = 0, from_ = 0;
  bool ended_ = false;
};

// Answers one section's order: sends each chunk as soon as it is formatted and goes on formatting
// while rank 0 takes them (or writes the runs before this rank's), up to kReadAheadBytes ahead.
void answer_section_order(const std::string& bytes, const std::map<int, OwnBulk>& own) {
  SectionOrder order;
  if (!order.read(bytes)) order = {};  // no runs: rank 0 finds none of the text it ordered
  std::vector<std::optional<std::vector<FaceAcross>>> across(order.pieces.size());
  if (order.lines == RowLines::tetgen_neigh)
    for (auto& faces : across) faces = values_of<FaceAcross>(receive_from(0, kRootSeconds));
  std::vector<std::optional<GivenPoints>> given(order.pieces.size());
  for (std::size_t run = 0; run < given.size(); ++run)
    if (order.pieces[run] == kGivenPoints) given[run] = receive_given_points();
  RunChunks chunks(std::move(order), std::move(across), std::move(given), own);
  SendQueue sent(0, kTagText, job_comm(), kRootSeconds);
  while (!chunks.done()) {
    while (sent.bytes_waiting() >= kReadAheadBytes) bounded([&] { sent.wait_oldest(); });
    sent.push(chunks.next());
  }
  bounded([&] { sent.wait_all(); });
}

}  // namespace

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
