#include "mpi/rank_writes.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <exception>
#include <functional>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "common/log.hpp"
#include "common/paths.hpp"
#include "common/test_hooks.hpp"
#include "io/buffered_file.hpp"
#include "io/parallel_hdf5.hpp"
#include "io/tetgen_files.hpp"
#include "io/xdmf.hpp"
#include "job/job.hpp"
#include "mpi/collective_watch.hpp"
#include "mpi/ranks.hpp"
#include "mpi/set_check.hpp"
#include "mpi/spread_piece_files.hpp"
#include "mpi/spread_row_files.hpp"
#include "mpi/write_messages.hpp"
#include "partet/errors.hpp"
#include "runner/serialize.hpp"
#include "stages/spread_mesh.hpp"

namespace partet::mpi {
namespace {

constexpr const char* kSpreadOrder = "hdf5-spread";
constexpr const char* kAgainOrder = "again";  // the last write failed; the files are written again
// Bytes of text per message: rank 0 holds one such chunk at a time beside the mesh.
constexpr std::size_t kTextChunk = std::size_t{8} << 20;
// Rows per part of a block (32 MB of .node rows, 16 MB of .ele rows).
constexpr std::size_t kRowPart = std::size_t{1} << 20;

// Every rank's part of an XDMF set's HDF5 files, under a watch: a rank stopped inside the
// parallel write would hold the others there (collective_watch.hpp). `write` writes them, calling
// its argument after each step every rank takes part in.
template <class Write>
MeshTotals watched_write(const Hdf5Paths& paths, Write write) {
  CollectiveWatch watch("writing '" + paths.mesh_shown + "' and '" + paths.boundary_shown + "'");
  return write(std::function<void()>([&watch] { watch.step(); }));
}

// How many parts the block of rows [first, last) travels in: kRowPart rows each, the last
// shorter; an empty block is one empty part. Sender and receiver both count by this.
std::size_t row_part_count(std::size_t first, std::size_t last) {
  return std::max<std::size_t>(1, (last - first + kRowPart - 1) / kRowPart);
}

// A block of the HDF5 files goes to its rank as a header ("B", or "" when rank 0 cannot make it),
// then its six arrays' bytes, straight from the mesh (mesh_block_view): no copy of it on either
// side.
constexpr int kBlockArrays = 6;

void send_block(const MeshBlockView& block, bool ok, int rank) {
  const auto send = [rank](const auto& run) {
    const std::string_view bytes(reinterpret_cast<const char*>(run.data), run.size * sizeof(*run.data));
    send_to(rank, bytes, kWorkerSeconds);
  };
  send_to(rank, ok ? "B" : "", kWorkerSeconds);
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
    const auto receive_one = [] { return receive_from(0, kRootSeconds); };
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
  return watched_write(paths, [&](const std::function<void()>& step) {
    return write_mesh_hdf5(job_comm(), own, paths, ok ? WriteTrouble::none : WriteTrouble::no_block, step);
  });
}

// The rows of bulks (their points at the input's scale) as runs, with their cell data (made into
// `columns`, which must outlive the runs).
void add_bulk_runs(std::vector<std::pair<const SpreadBulk*, const TetBlock*>> bulks,
                   std::vector<std::vector<std::int32_t>>& columns, MeshRowRuns& runs) {
  columns.reserve(2 * bulks.size());
  for (auto [place, bulk] : bulks) {
    if (static_cast<std::int64_t>(bulk->steiner_points.size()) != place->points)
      throw InternalError("the bulk of piece " + std::to_string(place->piece) + " does not match its placement");
    std::vector<std::int32_t>& solid = columns.emplace_back();
    std::vector<std::int32_t>& piece = columns.emplace_back();
    bulk_columns(*bulk, *place, solid, piece);
    runs.points.push_back({static_cast<std::uint64_t>(place->first_point), run_of(bulk->steiner_points)});
    runs.tets.push_back(
        {static_cast<std::uint64_t>(place->first_tet), run_of(bulk->tets), run_of(solid), run_of(piece), bulk->ids});
  }
}

// Rank 0's runs of the healed band: all of it, or the chains it healed when the others stayed on
// the ranks that healed them.
void add_band_runs(const SpreadMesh& mesh, MeshRowRuns& runs) {
  if (!mesh.band_elsewhere()) {
    runs.tets.push_back({static_cast<std::uint64_t>(mesh.first_band_tet), run_of(mesh.band_tets),
                         run_of(mesh.band_solid), run_of(mesh.band_piece), mesh.band_ids()});
    return;
  }
  for (const BandRun& run : mesh.band_runs) {
    if (run.rank != 0) continue;
    const auto from = static_cast<std::size_t>(run.first_here), count = static_cast<std::size_t>(run.tets);
    if (from + count > mesh.band_tets.size()) throw InternalError("a healed seam chain's rows are not in the band");
    runs.tets.push_back({static_cast<std::uint64_t>(run.first_row),
                         {mesh.band_tets.data() + from, count},
                         {mesh.band_solid.data() + from, count},
                         {mesh.band_piece.data() + from, count},
                         mesh.band_ids()});
  }
}

// The rows of the healed chains this rank kept (the placement's runs on it), with their cell data
// (made into `columns`, which must outlive the runs).
void add_kept_chain_runs(const std::vector<BandRun>& places, std::map<int, HealedChain>& chains,
                         std::vector<std::vector<std::int32_t>>& columns, MeshRowRuns& runs) {
  std::size_t found = 0;
  for (const BandRun& place : places) {
    if (place.rank != my_rank()) continue;
    const auto it = chains.find(place.chain);
    if (it == chains.end())
      throw InternalError("rank " + std::to_string(my_rank()) + " keeps no seam chain " + std::to_string(place.chain));
    const HealedChain& chain = it->second;
    ++found;
    if (static_cast<std::int64_t>(chain.tets.size()) != place.tets || chain.label.size() != chain.tets.size() ||
        place.point_ids.size() != chain.global_ids.size() + chain.new_points.size())
      throw InternalError("seam chain " + std::to_string(place.chain) + " does not match its placement");
    std::vector<std::int32_t>& solid = columns.emplace_back();
    for (const std::int32_t component : chain.label)
      solid.push_back(place.solid.at(static_cast<std::size_t>(component)));
    std::vector<std::int32_t>& piece = columns.emplace_back(chain.piece);
    if (piece.empty()) piece.assign(chain.tets.size(), -1);
    runs.tets.push_back({static_cast<std::uint64_t>(place.first_row), run_of(chain.tets), run_of(solid), run_of(piece),
                         PointIds{0, 0, place.point_ids.data()}});
  }
  if (found != chains.size())
    throw InternalError("rank " + std::to_string(my_rank()) + " keeps a seam chain rank 0 did not place");
}

// Rank 0's Hdf5Write for a mesh left spread: it tells the owners where every bulk's rows are, then
// every rank writes its own rows at once: rank 0 the split surface's points, the points healing
// added, the healed band, its own bulks and the boundary; each other rank the bulks it keeps.
MeshTotals write_spread_on_every_rank(SpreadMesh& mesh, int exponent, const MeshOutput& output,
                                      const Hdf5Paths& relative) {
  Hdf5Paths paths = relative;
  paths.mesh = absolute_or_error(relative.mesh), paths.boundary = absolute_or_error(relative.boundary);
  const MeshTotals totals{static_cast<std::uint64_t>(mesh.points), static_cast<std::uint64_t>(mesh.tets),
                          output.boundary.size()};
  const std::string placement = serialize_placement(mesh.bulks);  // before the order: no rank waits for it
  const std::string band_placement = serialize_band_runs(mesh.band_runs, true);
  broadcast_text(std::string(kSpreadOrder) + "\n" + paths.mesh + '\n' + paths.boundary + '\n' + paths.mesh_shown +
                 '\n' + paths.boundary_shown + '\n' + std::to_string(exponent) + '\n' + std::to_string(totals.points) +
                 '\n' + std::to_string(totals.tets) + '\n' + std::to_string(totals.faces));
  broadcast_text(placement);
  broadcast_text(band_placement);
  // Rows rank 0 cannot make go as none, so every rank still joins the write and fails there.
  MeshRowRuns runs;
  std::vector<std::vector<std::int32_t>> columns;
  std::vector<std::int32_t> markers;
  WriteTrouble trouble = WriteTrouble::none;
  try {
    runs.points.push_back({0, run_of(mesh.split_points)});
    runs.points.push_back({static_cast<std::uint64_t>(mesh.first_healing_point), run_of(mesh.healing_points)});
    std::vector<std::pair<const SpreadBulk*, const TetBlock*>> own;
    for (SpreadBulk& bulk : mesh.bulks)
      if (bulk.here) own.push_back({&bulk, &bulk.block});
    add_bulk_runs(own, columns, runs);
    add_band_runs(mesh, runs);
    markers.resize(output.boundary.size());
    for (std::size_t f = 0; f < markers.size(); ++f) markers[f] = f < output.split_from ? 1 : 2;
    runs.faces = run_of(output.boundary);
    runs.face_marker = run_of(markers);
  } catch (const std::exception& e) {
    log::error(e.what());
    runs = MeshRowRuns();
    trouble = WriteTrouble::no_block;
  }
  return watched_write(paths, [&](const std::function<void()>& step) {
    return write_mesh_runs_hdf5(job_comm(), runs, totals, paths, trouble, step);
  });
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
      send_to(r, part, kWorkerSeconds);
    }
  }
  std::exception_ptr failure;
  try {
    const auto [first, last] = run_of(rows.count, 0, size);
    write_tetgen_lines(rows, first, last - first, out);
  } catch (...) {
    failure = std::current_exception();
  }
  for (int r = 1; r < size; ++r) take_text_chunks(out, r, failure);
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
  for (std::string& part : parts) part = receive_from(0, kRootSeconds);
  const auto kind = static_cast<TetgenFile>(file);
  const std::size_t bytes_per_row = row_bytes(kind);
  auto send = [](const std::string& chunk) { send_to(0, chunk, kRootSeconds); };
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
    for (int rank = 1; rank < size_; ++rank) send_to(rank, "", kWorkerSeconds);  // no more files
    if (failure_) std::rethrow_exception(failure_);
  }

 private:
  void find_writers() {
    for (int rank = 1; rank < size_; ++rank)
      if (receive_from(rank, kWorkerSeconds) == "1") writers_.push_back(rank);
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
    send_to(rank, arrays ? "B" + std::to_string(i) + "/" + std::to_string(arrays->size()) : "N" + std::to_string(i),
            kWorkerSeconds);
    if (arrays)
      for (std::string_view bytes : *arrays) send_to(rank, bytes, kWorkerSeconds);
    busy_[rank] = true;
  }

  static bool answered(int rank) {
    int arrived = 0;
    MPI_Iprobe(rank, kTagText, job_comm(), &arrived, MPI_STATUS_IGNORE);
    return arrived != 0;
  }

  void take_answer(int rank) {
    const std::string answer = receive_from(rank, kWorkerSeconds);
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
  for (std::string& bytes : arrays) bytes = receive_from(0, kRootSeconds);
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
  send_to(0, fd >= 0 ? "1" : "0", kRootSeconds);
  for (;;) {
    const std::string header = receive_from(0, kRootSeconds);
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
    send_to(0, answer, kRootSeconds);
  }
}

// A worker's side of a spread mesh's HDF5 files: the rows of the bulks it keeps.
void join_spread_write(std::istringstream& lines, JobStatus& status, BulksForWrites& kept) {
  Hdf5Paths paths;
  std::string exponent, points, tets, faces;
  std::getline(lines, paths.mesh), std::getline(lines, paths.boundary);
  std::getline(lines, paths.mesh_shown), std::getline(lines, paths.boundary_shown);
  std::getline(lines, exponent), std::getline(lines, points), std::getline(lines, tets), std::getline(lines, faces);
  const std::string placement = broadcast_text("");
  const std::string band_placement = broadcast_text("");
  WriteTrouble trouble = WriteTrouble::none;
  MeshRowRuns runs;
  std::vector<std::vector<std::int32_t>> columns;
  std::vector<SpreadBulk> places;
  std::vector<BandRun> band_places;
  try {
    places = deserialize_placement(placement);
    band_places = deserialize_band_runs(band_placement);
    const std::map<int, TetBlock>& bulks = kept.get(std::stoi(exponent));
    std::vector<std::pair<const SpreadBulk*, const TetBlock*>> mine;
    for (const SpreadBulk& place : places)
      if (auto it = bulks.find(place.piece); it != bulks.end()) mine.push_back({&place, &it->second});
    if (mine.size() != bulks.size())
      throw InternalError("rank " + std::to_string(my_rank()) + " keeps a bulk rank 0 did not place");
    add_bulk_runs(mine, columns, runs);
    add_kept_chain_runs(band_places, kept.chains(), columns, runs);
  } catch (const std::exception& e) {
    log::error(e.what());
    trouble = WriteTrouble::no_block;
  }
  if (test_hooks::block_lost(my_rank())) trouble = WriteTrouble::no_block;
  test_hooks::kept_bulk_stop(my_rank(), "write");
  try {
    const MeshTotals totals{std::stoull(points), std::stoull(tets), std::stoull(faces)};
    watched_write(paths, [&](const std::function<void()>& step) {
      return write_mesh_runs_hdf5(job_comm(), runs, totals, paths, trouble, step);
    });
  } catch (const std::exception& e) {
    status.error = e.what();  // rank 0 has the same error and reports it
  }
}

// A worker's side of the HDF5 files of an XDMF set.
void join_hdf5_write(std::istringstream& lines, JobStatus& status) {
  Hdf5Paths paths;
  std::getline(lines, paths.mesh), std::getline(lines, paths.boundary);
  std::getline(lines, paths.mesh_shown), std::getline(lines, paths.boundary_shown);
  const ReceivedBlock received = ReceivedBlock::receive();
  std::optional<MeshBlockView> block = received.view();
  if (test_hooks::block_lost(my_rank())) block.reset();
  test_hooks::kept_bulk_stop(my_rank(), "write");
  try {
    watched_write(paths, [&](const std::function<void()>& step) {
      return write_mesh_hdf5(job_comm(), block.value_or(MeshBlockView()), paths,
                             block ? WriteTrouble::none : WriteTrouble::no_block, step);
    });
  } catch (const std::exception& e) {
    status.error = e.what();  // rank 0 has the same error and reports it
  }
}

}  // namespace

RankWriters rank_writers(int size, RankStats& stats, SpreadMesh* spread, int scale_exponent) {
  RankWriters writers;
  writers.hdf5 = write_hdf5_on_every_rank;
  if (spread) {
    writers.hdf5 = [spread, scale_exponent](const MeshOutput& output, const Hdf5Paths& paths) {
      return write_spread_on_every_rank(*spread, scale_exponent, output, paths);
    };
    writers.spread_pieces = piece_values(*spread);
    writers.spread_piece_files = [spread, scale_exponent, &stats](
                                     MeshFormat format, const std::vector<PieceFile>& files, const MeshOutput& output) {
      write_spread_piece_files(format, *spread, output, scale_exponent, files, stats);
    };
    writers.spread_rows = [spread, scale_exponent](OutputSet& set, MeshFormat format, const MeshOutput& output,
                                                   const std::string& prefix) {
      add_spread_row_files(set, format, *spread, output, prefix, scale_exponent, write_tetgen_lines_on_every_rank);
    };
  }
  if (size > 1) writers.tetgen_lines = write_tetgen_lines_on_every_rank;
  writers.again = [] { broadcast_text(kAgainOrder); };
  writers.piece_files = [&stats](MeshFormat format, const std::vector<PieceFile>& files,
                                 const PieceArraysOf& arrays_of) {
    PieceFileDealer(format, files, arrays_of, stats).run();
  };
  return writers;
}

void end_writes() { broadcast_text(""); }

void join_writes(JobStatus& status, RankStats& stats, const KeptBulksTaker& take_bulks,
                 const KeptChainsTaker& take_chains) {
  const AddSeconds timer{stats.write_seconds};
  BulksForWrites kept(take_bulks, take_chains);
  const std::string error_before = status.error;
  for (std::string order = broadcast_text(""); !order.empty(); order = broadcast_text("")) {
    std::istringstream lines(order);
    std::string kind;
    std::getline(lines, kind);
    if (kind == "hdf5")
      join_hdf5_write(lines, status);
    else if (kind == kSpreadOrder)
      join_spread_write(lines, status, kept);
    else if (kind == kSpreadPiecesOrder)
      write_own_piece_files(lines, kept, stats);
    else if (kind == kSpreadRowsOrder)
      stream_own_rows(lines, kept);
    else if (kind == kPiecesOrder)
      write_piece_files_sent(lines, stats);
    else if (kind == kSetCheckOrder)
      join_set_check(lines, status);
    else if (kind == kAgainOrder)
      status.error = error_before;  // (rank 0 waited for room after a full disk)
    else
      format_rows_block(lines);
  }
}

}  // namespace partet::mpi
