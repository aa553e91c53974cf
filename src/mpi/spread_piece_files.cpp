#include "mpi/spread_piece_files.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <exception>
#include <optional>
#include <string>
#include <type_traits>

#include "common/id_bits.hpp"
#include "common/log.hpp"
#include "common/test_hooks.hpp"
#include "io/msh.hpp"
#include "job/job.hpp"
#include "mpi/ranks.hpp"
#include "mpi/write_messages.hpp"
#include "partet/errors.hpp"
#include "runner/serialize.hpp"

namespace partet::mpi {
namespace {

// What the order tells every rank of the set besides its files.
struct SetOrder {
  MeshFormat format = MeshFormat::pvtu;
  std::uint64_t boundary = 0;  // boundary triangles (MSH: a tet's element tag is boundary + row + 1)
  std::size_t split_from = 0;  // the boundary's parts of split input triangles from here
  bool msh() const { return format != MeshFormat::pvtu; }
  // The head of the MSH partition of file `file` (partition file + 1).
  MshPartHead head(std::size_t file, std::size_t files, const Bounds& model) const {
    return {file + 1, files, boundary, split_from, format == MeshFormat::msh_parts_binary, model};
  }
};

// A .pvtu file's cells from its piece's bulk (if any) and the band's tets of that piece, in row order.
VtuCells cells_of(int piece, const TetBlock* bulk, const std::vector<std::int32_t>& bulk_solid,
                  const std::vector<GlobalTet>& band, const std::vector<std::int32_t>& band_solid) {
  const CompactTets compact = compact_tets(band);
  std::vector<TetsWithRegion> blocks;
  if (bulk) blocks.push_back({&bulk->tets, &bulk_solid, bulk->ids});
  blocks.push_back({&compact.tets, &band_solid, compact.ids()});
  return piece_file_cells(piece, blocks);
}

// An MSH partition's tets: its piece's bulk (if any, rows from first_row), then the band's tets
// of that piece (at band_rows).
MshPartTets part_tets(const TetBlock* bulk, std::int64_t first_row, const std::vector<GlobalTet>& band,
                      const std::vector<std::int64_t>& band_rows) {
  const std::size_t own = bulk ? bulk->tets.size() : 0;
  return {own + band.size(),
          [bulk, own, &band](std::size_t i) { return i < own ? bulk->ids(bulk->tets[i]) : band[i - own]; },
          [first_row, own, &band_rows](std::size_t i) {
            return i < own ? first_row + static_cast<std::int64_t>(i) : band_rows[i - own];
          }};
}

// A bulk's open faces (every face when it kept no neighbours) of the split surface's points,
// vertices ascending: rank 0 finds its boundary triangles among them (a face with a Steiner point
// is none; in a bulk's compact ids, the split surface's are the mesh's own).
std::vector<std::array<std::int32_t, 3>> open_faces(const TetBlock& bulk) {
  std::vector<std::array<std::int32_t, 3>> faces;
  const bool known = bulk.neighbours.size() == bulk.tets.size();
  for (std::size_t t = 0; t < bulk.tets.size(); ++t)
    for (int j = 0; j < 4; ++j)
      if (!known || bulk.neighbours[t][j] < 0) {
        const FaceKey key(outward_face(bulk.tets[t], j));
        if (key.v[2] < bulk.ids.from) faces.push_back({key.v[0], key.v[1], key.v[2]});
      }
  return faces;
}

std::string bounds_bytes(const Bounds& b) {
  const std::vector<double> v{b.min[0], b.min[1], b.min[2], b.max[0], b.max[1], b.max[2]};
  return std::string(bytes_of(run_of(v)));
}

std::optional<Bounds> bounds_from(const std::string& bytes) {
  const std::optional<std::vector<double>> v = values_of<double>(bytes);
  if (!v || v->size() != 6) return std::nullopt;
  return Bounds{{(*v)[0], (*v)[1], (*v)[2]}, {(*v)[3], (*v)[4], (*v)[5]}};
}

// ---------------------------------------------------------------------------------------------
// Rank 0

class SpreadPieceFileWrite {
 public:
  SpreadPieceFileWrite(MeshFormat format, const SpreadMesh& mesh, const MeshOutput& output, int exponent,
                       const std::vector<PieceFile>& files, RankStats& stats)
      : set_{format, output.boundary.size(), std::min(output.split_from, output.boundary.size())},
        mesh_(mesh),
        output_(output),
        exponent_(exponent),
        files_(files),
        stats_(stats) {
    MPI_Comm_size(job_comm(), &size_);
    claims_.resize(static_cast<std::size_t>(size_));
    int highest = 0;
    for (const PieceFile& file : files_) highest = std::max(highest, file.piece);
    file_by_piece_.assign(static_cast<std::size_t>(highest) + 2, -1);
    for (std::size_t i = 0; i < files_.size(); ++i)
      if (files_[i].piece >= -1) file_by_piece_[files_[i].piece + 1] = static_cast<std::int64_t>(i);
  }

  void run() {
    // 1. The order, and which rank writes which file.
    const std::string placement = serialize_placement(mesh_.bulks);  // before the order: no rank waits for it
    broadcast_text(order());
    broadcast_text(placement);
    take_claims();
    // 2. MSH partitions: each one's boundary triangles, found among the open faces of its tets
    //    (the owners send their bulks'), and the whole mesh's bounds.
    if (set_.msh()) take_boundary();
    // 3. What the owners need of rank 0: the band's tets of their pieces, then their points' coordinates.
    for (int rank = 1; rank < size_; ++rank)
      for (const Claim& claim : claims_[rank]) send_band_part(rank, claim);
    for (int rank = 1; rank < size_; ++rank) answer_points(rank);
    // 4. Every rank writes its files at once; rank 0 then takes the others' answers.
    for (std::size_t i = 0; i < files_.size(); ++i)
      if (!claimed_[i]) write_own(i);
    for (int rank = 1; rank < size_; ++rank)
      for (const Claim& claim : claims_[rank]) take_answer(rank, claim);
    if (failure_) std::rethrow_exception(failure_);
  }

 private:
  std::string order() const {
    std::string order = std::string(kSpreadPiecesOrder) + '\n' + std::to_string(exponent_) + '\n' +
                        mesh_format_name(set_.format) + '\n' + std::to_string(set_.boundary) + '\n' +
                        std::to_string(set_.split_from) + '\n';
    for (const PieceFile& file : files_)
      order += std::to_string(file.piece) + '\0' + absolute_or_error(file.temporary) + '\0' + file.shown + '\0';
    return order;
  }

  void fail(std::exception_ptr failure) {
    if (!failure_) failure_ = failure;
  }

  const SpreadBulk* bulk_of(int piece) const {
    for (const SpreadBulk& bulk : mesh_.bulks)
      if (bulk.piece == piece) return &bulk;
    return nullptr;
  }

  // A file a rank says it writes; not `valid` when it cannot be (the rank is still answered for
  // it, so the exchange stays in step, and the write fails).
  struct Claim {
    std::size_t file = 0;
    bool valid = false;
  };

  void take_claims() {
    claimed_.assign(files_.size(), false);
    for (int rank = 1; rank < size_; ++rank) {
      std::vector<std::int64_t> claimed;
      if (auto values = values_of<std::int64_t>(receive_from(rank, kWorkerSeconds))) claimed = std::move(*values);
      for (std::int64_t i : claimed) {
        const bool known = i >= 0 && i < static_cast<std::int64_t>(files_.size());
        const SpreadBulk* bulk = known ? bulk_of(files_[i].piece) : nullptr;
        const bool valid = bulk && !bulk->here && !claimed_[i];
        if (!valid)
          fail(std::make_exception_ptr(
              InternalError("rank " + std::to_string(rank) + " claims a piece file it cannot write")));
        if (valid) claimed_[i] = true;
        claims_[rank].push_back({known ? static_cast<std::size_t>(i) : 0, valid});
      }
    }
  }

  // The file of the partition (or piece) value `piece`.
  std::uint32_t file_of(int piece) const {
    const std::size_t slot = static_cast<std::size_t>(piece) + 1;
    if (piece < -1 || slot >= file_by_piece_.size() || file_by_piece_[slot] < 0)
      throw InternalError("no MSH partition holds piece " + std::to_string(piece));
    return static_cast<std::uint32_t>(file_by_piece_[slot]);
  }

  // Every owner's bulks' bounds and open faces (per claim), then rank 0's own tets' faces.
  void take_boundary() {
    std::map<int, Bounds> bounds;  // of the bulks kept elsewhere
    try {
      boundary_.emplace(output_.boundary);
    } catch (...) {  // (out of memory) every rank is still heard out
      fail(std::current_exception());
    }
    for (int rank = 1; rank < size_; ++rank)
      for (const Claim& claim : claims_[rank]) {
        const std::optional<Bounds> box = bounds_from(receive_from(rank, kWorkerSeconds));
        const auto faces = values_of<std::array<std::int32_t, 3>>(receive_from(rank, kWorkerSeconds));
        if (!claim.valid) continue;
        if (!box || !faces) {
          fail(std::make_exception_ptr(
              InternalError("rank " + std::to_string(rank) + " sent its bulk's faces wrongly")));
          continue;
        }
        bounds[files_[claim.file].piece] = *box;
        if (boundary_) boundary_->add_faces(*faces, static_cast<std::uint32_t>(claim.file));
      }
    if (!boundary_) return;
    try {
      std::vector<std::uint32_t> band_file(mesh_.band_tets.size());  // found here: file_of throws
      for (std::size_t t = 0; t < band_file.size(); ++t) band_file[t] = file_of(mesh_.band_piece[t]);
      boundary_->add_tets(mesh_.band_tets, mesh_.band_neighbours, [&](std::size_t t) { return band_file[t]; });
      for (const SpreadBulk& bulk : mesh_.bulks)
        if (bulk.here && bulk.tets > 0) {
          const std::uint32_t file = file_of(bulk.piece);
          boundary_->add_tets(bulk.block.tets, bulk.block.neighbours, [file](std::size_t) { return file; });
        }
      boundary_->group(files_.size());
      model_ = bounds_of_rows(mesh_, [&](const SpreadBulk& bulk) {
        const auto found = bounds.find(bulk.piece);
        if (found == bounds.end()) throw InternalError("no rank keeps the bulk of piece " + std::to_string(bulk.piece));
        return found->second;
      });
      grouped_ = true;
    } catch (...) {
      fail(std::current_exception());
    }
  }

  // A partition's boundary triangles, as rows.
  std::vector<std::uint64_t> boundary_rows(std::size_t file) const {
    if (!grouped_) throw InternalError("the boundary was not split into MSH partitions");
    return boundary_->rows(file);
  }

  void send_band_part(int rank, const Claim& claim) {
    std::vector<GlobalTet> tets;
    std::vector<std::int32_t> solid;
    std::vector<std::int64_t> rows;
    std::vector<std::uint64_t> triangles;
    try {
      if (!claim.valid) throw InternalError("no band part for a piece file claimed wrongly");
      band_tets_of(mesh_, files_[claim.file].piece, tets, solid, &rows);
      if (set_.msh()) triangles = boundary_rows(claim.file);
    } catch (...) {  // (out of memory) the rank is still told, so it does not wait
      fail(std::current_exception());
      send_to(rank, "N", kWorkerSeconds);
      return;
    }
    send_to(rank, "B", kWorkerSeconds);
    send_to(rank, bytes_of(run_of(tets)), kWorkerSeconds);
    send_to(rank, bytes_of(run_of(solid)), kWorkerSeconds);
    if (!set_.msh()) return;
    send_to(rank, bytes_of(run_of(rows)), kWorkerSeconds);
    send_to(rank, bytes_of(run_of(triangles)), kWorkerSeconds);
    send_to(rank, bounds_bytes(model_), kWorkerSeconds);
  }

  // The coordinates of the points a rank asks for, or "" when rank 0 cannot give them.
  void answer_points(int rank) {
    const std::string asked = receive_from(rank, kWorkerSeconds);
    std::vector<double> xyz;
    try {
      const std::optional<std::vector<std::int64_t>> ids = values_of<std::int64_t>(asked, 1);
      if (asked.empty() || asked[0] != 'I' || !ids) throw InternalError("a malformed request for points");
      xyz.reserve(3 * ids->size());
      for (std::int64_t id : *ids) {
        const Point3 p = point_of(mesh_, id);
        xyz.insert(xyz.end(), p.begin(), p.end());
      }
    } catch (...) {
      fail(std::current_exception());
      xyz.clear();
    }
    send_to(rank, xyz.empty() ? std::string_view() : bytes_of(run_of(xyz)), kWorkerSeconds);
  }

  // The seams' file and those of the bulks rank 0 keeps (a bulk elsewhere that no rank claimed is
  // a failure).
  void write_own(std::size_t index) {
    if (failure_) return;
    const PieceFile& file = files_[index];
    try {
      const SpreadBulk* bulk = file.piece < 0 ? nullptr : bulk_of(file.piece);
      if (bulk && !bulk->here && bulk->tets > 0)
        throw InternalError("no rank wrote the piece file of piece " + std::to_string(file.piece));
      const TetBlock* tets = bulk && bulk->here ? &bulk->block : nullptr;
      std::vector<GlobalTet> band;
      std::vector<std::int32_t> band_solid;
      std::vector<std::int64_t> band_rows;
      band_tets_of(mesh_, file.piece, band, band_solid, &band_rows);
      if (set_.msh()) {
        const MshPartArrays part = msh_part_arrays(
            set_.head(index, files_.size(), model_), part_tets(tets, tets ? bulk->first_tet : 0, band, band_rows),
            boundary_rows(index), [&](std::int64_t id) { return point_of(mesh_, id); });
        write_msh_part(part.view(), file.temporary, file.shown);
        ++stats_.piece_files_written;
        return;
      }
      std::vector<std::int32_t> bulk_solid, bulk_piece;
      if (tets) bulk_columns(*tets, *bulk, bulk_solid, bulk_piece);
      VtuCells cells = cells_of(file.piece, tets, bulk_solid, band, band_solid);
      for (std::int64_t id : cells.global_ids) {
        const Point3 p = point_of(mesh_, id);
        cells.xyz.insert(cells.xyz.end(), p.begin(), p.end());
      }
      write_vtu_file(cells.view(), file.temporary, file.shown);
      ++stats_.piece_files_written;
    } catch (...) {
      fail(std::current_exception());
    }
  }

  void take_answer(int rank, const Claim& claim) {
    const std::string answer = receive_from(rank, kRootSeconds);  // a large file takes long to write
    if (answer.empty()) return;
    if (answer[0] == 'E') return fail(std::make_exception_ptr(OutputError(answer.substr(1))));
    // "A": the rank cannot open the file's temporary; rank 0 writes the arrays it sent.
    std::vector<std::string> arrays(answer[0] == 'A' ? std::stoul(answer.substr(1)) : 0);
    for (std::string& bytes : arrays) bytes = receive_from(rank, kWorkerSeconds);
    if (failure_ || !claim.valid) return;
    const PieceFile& file = files_[claim.file];
    try {
      write_piece_file(set_.format, PieceArrays(arrays.begin(), arrays.end()), file.temporary, file.shown);
      ++stats_.piece_files_written;
    } catch (...) {
      fail(std::current_exception());
    }
  }

  const SetOrder set_;
  const SpreadMesh& mesh_;
  const MeshOutput& output_;
  int exponent_ = 0;
  const std::vector<PieceFile>& files_;
  RankStats& stats_;
  int size_ = 1;
  std::vector<std::vector<Claim>> claims_;  // per rank: the files it writes
  std::vector<bool> claimed_;               // per file: another rank writes it
  std::exception_ptr failure_;
  // MSH partitions: the boundary triangles by partition (= file), and the whole mesh's bounds.
  std::optional<MshBoundaryParts> boundary_;
  bool grouped_ = false;
  Bounds model_;
  std::vector<std::int64_t> file_by_piece_;  // slot piece + 1: its file, or -1
};

// ---------------------------------------------------------------------------------------------
// The other ranks

struct OwnFile {
  PieceFile file;
  TetBlock* bulk = nullptr;
  const SpreadBulk* place = nullptr;
  std::size_t index = 0;  // in the order's files
  std::vector<GlobalTet> band;
  std::vector<std::int32_t> band_solid;
  // MSH partitions: the band tets' rows, the partition's boundary triangles as rows, the whole mesh's bounds.
  std::vector<std::int64_t> band_rows;
  std::vector<std::uint64_t> triangles;
  Bounds model;
  bool received = false;
};

// Its band part as rank 0 sent it ("B", tets, solids, and for MSH the tets' rows, the boundary
// triangles and the bounds; or "N").
void receive_band_part(const SetOrder& set, OwnFile& own) {
  if (receive_from(0, kRootSeconds) != "B") return;
  const std::optional<std::vector<GlobalTet>> tets = values_of<GlobalTet>(receive_from(0, kRootSeconds));
  const std::optional<std::vector<std::int32_t>> solid = values_of<std::int32_t>(receive_from(0, kRootSeconds));
  bool whole = tets && solid && tets->size() == solid->size();
  if (set.msh()) {  // every message taken, so the exchange stays in step
    const auto rows = values_of<std::int64_t>(receive_from(0, kRootSeconds));
    const auto triangles = values_of<std::uint64_t>(receive_from(0, kRootSeconds));
    const std::optional<Bounds> model = bounds_from(receive_from(0, kRootSeconds));
    whole = whole && rows && triangles && model && rows->size() == tets->size() && triangles->size() % 4 == 0;
    if (whole) own.band_rows = *rows, own.triangles = *triangles, own.model = *model;
  }
  if (!whole) return;
  own.band = *tets, own.band_solid = *solid;
  own.received = !test_hooks::block_lost(my_rank());
}

// The points the files use that this rank does not keep (outside its bulks' Steiner rows), ascending.
std::vector<std::int64_t> points_asked(const std::vector<OwnFile>& files) {
  return distinct_ascending<std::int64_t>([&](const auto& use) {
    const auto add = [&](std::int64_t v, const SpreadBulk& place) {
      if (v < place.first_point || v >= place.first_point + place.points) use(static_cast<std::uint64_t>(v));
    };
    for (const OwnFile& own : files) {
      for (const Tet& t : own.bulk->tets)
        for (std::int32_t v : t) add(own.bulk->ids(v), *own.place);
      for (const GlobalTet& t : own.band)
        for (std::int64_t v : t) add(v, *own.place);
    }
  });
}

// A point's coordinates on this rank: its bulk's Steiner points, else those asked of rank 0.
Point3 point_here(const OwnFile& own, const std::vector<std::int64_t>& asked, const std::vector<double>& xyz,
                  std::int64_t id) {
  const SpreadBulk& place = *own.place;
  if (id >= place.first_point && id < place.first_point + place.points)
    return own.bulk->steiner_points[id - place.first_point];
  const auto at = std::lower_bound(asked.begin(), asked.end(), id);
  if (at == asked.end() || *at != id) throw InternalError("a piece file's point was not asked for");
  const double* p = xyz.data() + 3 * (at - asked.begin());
  return {p[0], p[1], p[2]};
}

// Writes one file into its temporary, or, when this rank cannot open it (a directory local to rank
// 0's node), sends its arrays to rank 0 and says how many ("A" + the number).
template <class View>
void write_or_send(const View& view, const PieceFile& file, RankStats& stats) {
  const int fd = ::open(file.temporary.c_str(), O_WRONLY | O_CLOEXEC);  // never creates it
  if (fd < 0) {
    const PieceArrays arrays = arrays_of(view);
    send_to(0, "A" + std::to_string(arrays.size()), kRootSeconds);
    for (std::string_view bytes : arrays) send_to(0, bytes, kRootSeconds);
    return;
  }
  ::close(fd);
  if constexpr (std::is_same_v<View, MshPartView>)
    write_msh_part(view, file.temporary, file.shown);
  else
    write_vtu_file(view, file.temporary, file.shown);
  ++stats.piece_files_written;
  send_to(0, "", kRootSeconds);
}

// Writes one file (or sends its arrays to rank 0) and answers for it.
void write_one(const SetOrder& set, std::size_t files, OwnFile& own, const std::vector<std::int64_t>& asked,
               const std::vector<double>& xyz, RankStats& stats) {
  try {
    if (!own.received)
      throw OutputError("rank " + std::to_string(my_rank()) + " did not receive the content of '" + own.file.shown +
                        "'");
    if (static_cast<std::int64_t>(own.bulk->steiner_points.size()) != own.place->points)
      throw InternalError("the bulk of piece " + std::to_string(own.place->piece) + " does not match its placement");
    test_hooks::write_out_of_memory(my_rank());
    const auto point = [&](std::int64_t id) { return point_here(own, asked, xyz, id); };
    if (set.msh()) {
      const MshPartArrays part = msh_part_arrays(set.head(own.index, files, own.model),
                                                 part_tets(own.bulk, own.place->first_tet, own.band, own.band_rows),
                                                 std::move(own.triangles), point);
      return write_or_send(part.view(), own.file, stats);
    }
    std::vector<std::int32_t> solid, piece;
    bulk_columns(*own.bulk, *own.place, solid, piece);
    VtuCells cells = cells_of(own.file.piece, own.bulk, solid, own.band, own.band_solid);
    for (std::int64_t id : cells.global_ids) {
      const Point3 p = point(id);
      cells.xyz.insert(cells.xyz.end(), p.begin(), p.end());
    }
    write_or_send(cells.view(), own.file, stats);
  } catch (const std::exception&) {
    send_to(0, "E" + error_message(std::current_exception(), my_rank()), kRootSeconds);
  }
}

}  // namespace

void write_spread_piece_files(MeshFormat format, const SpreadMesh& mesh, const MeshOutput& output, int exponent,
                              const std::vector<PieceFile>& files, RankStats& stats) {
  if (mesh.band_elsewhere()) throw InternalError("piece files were asked of a band left on the ranks that healed it");
  SpreadPieceFileWrite(format, mesh, output, exponent, files, stats).run();
}

std::map<int, HealedChain>& BulksForWrites::chains() {
  if (!chains_taken_ && take_chains_) chains_ = take_chains_();
  chains_taken_ = true;
  return chains_;
}

std::map<int, TetBlock>& BulksForWrites::get(int exponent) {
  if (!taken_) {
    taken_ = true;
    bulks_ = take_();
    if (exponent != 0)
      for (auto& [piece, bulk] : bulks_) scale_points(bulk.steiner_points, -exponent);
  }
  return bulks_;
}

namespace {

// The order's head and files (its first line read).
SetOrder read_order(std::istringstream& order, int& exponent, std::vector<PieceFile>& files) {
  std::string line, piece, temporary, shown;
  SetOrder set;
  std::getline(order, line), exponent = std::stoi(line);
  std::getline(order, line), set.format = mesh_format(line);
  std::getline(order, line), set.boundary = std::stoull(line);
  std::getline(order, line), set.split_from = std::stoull(line);
  while (std::getline(order, piece, '\0') && std::getline(order, temporary, '\0') && std::getline(order, shown, '\0'))
    files.push_back({std::stoi(piece), temporary, shown});
  return set;
}

// The files of the bulks this rank keeps (none when it cannot tell: rank 0 then finds files no
// rank claims, and fails).
std::vector<OwnFile> own_files(const std::vector<PieceFile>& files, const std::vector<SpreadBulk>& places,
                               std::map<int, TetBlock>& bulks) {
  std::vector<OwnFile> own;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const auto bulk = bulks.find(files[i].piece);
    const auto place =
        std::find_if(places.begin(), places.end(), [&](const SpreadBulk& p) { return p.piece == files[i].piece; });
    if (bulk == bulks.end() || place == places.end()) continue;
    OwnFile& file = own.emplace_back();
    file.file = files[i], file.bulk = &bulk->second, file.place = &*place, file.index = i;
  }
  return own;
}

// MSH partitions: per file, its bulk's bounds and open faces (an empty message when it cannot
// make them: rank 0 then fails).
void send_boundary_faces(const std::vector<OwnFile>& own) {
  for (const OwnFile& file : own) {
    std::string box, faces;
    try {
      box = bounds_bytes(bounds_of(file.bulk->steiner_points));
      faces = std::string(bytes_of(run_of(open_faces(*file.bulk))));
    } catch (const std::exception& e) {
      log::error(e.what());
      box.clear(), faces.clear();
    }
    send_to(0, box, kRootSeconds);
    send_to(0, faces, kRootSeconds);
  }
}

}  // namespace

void write_own_piece_files(std::istringstream& order, BulksForWrites& kept, RankStats& stats) {
  int exponent = 0;
  std::vector<PieceFile> files;
  const SetOrder set = read_order(order, exponent, files);
  const std::string placement = broadcast_text("");
  // 1. The files of the bulks this rank keeps; for MSH partitions, their bulks' open faces.
  std::vector<SpreadBulk> places;
  std::vector<OwnFile> own;
  std::vector<std::int64_t> claims;
  try {
    places = deserialize_placement(placement);
    own = own_files(files, places, kept.get(exponent));
  } catch (const std::exception& e) {
    log::error(e.what());
    own.clear();
  }
  for (const OwnFile& file : own) claims.push_back(static_cast<std::int64_t>(file.index));
  send_to(0, bytes_of(run_of(claims)), kRootSeconds);
  if (set.msh()) send_boundary_faces(own);
  // 2. The band's parts, then the coordinates of the points this rank lacks.
  for (OwnFile& file : own) receive_band_part(set, file);
  const std::vector<std::int64_t> asked = points_asked(own);
  std::string request = "I";
  request.append(bytes_of(run_of(asked)));
  send_to(0, request, kRootSeconds);
  const std::optional<std::vector<double>> xyz = values_of<double>(receive_from(0, kRootSeconds));
  const bool have_points = xyz && xyz->size() == 3 * asked.size();
  // 3. The files.
  for (OwnFile& file : own) {
    if (!have_points) file.received = false;
    write_one(set, files.size(), file, asked, have_points ? *xyz : std::vector<double>{}, stats);
  }
}

}  // namespace partet::mpi
