#include "mpi/spread_piece_files.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <exception>
#include <optional>
#include <string>

#include "common/log.hpp"
#include "common/test_hooks.hpp"
#include "job/job.hpp"
#include "mpi/ranks.hpp"
#include "mpi/write_messages.hpp"
#include "partet/errors.hpp"
#include "runner/serialize.hpp"

namespace partet::mpi {
namespace {

// A file's cells from its piece's bulk (if any) and the band's tets of that piece, in row order.
VtuCells cells_of(int piece, const TetBlock* bulk, const std::vector<std::int32_t>& bulk_solid,
                  const std::vector<Tet>& band, const std::vector<std::int32_t>& band_solid) {
  std::vector<TetsWithRegion> blocks;
  if (bulk) blocks.push_back({&bulk->tets, &bulk_solid});
  blocks.push_back({&band, &band_solid});
  return piece_file_cells(piece, blocks);
}

// ---------------------------------------------------------------------------------------------
// Rank 0

class SpreadPieceFileWrite {
 public:
  SpreadPieceFileWrite(const SpreadMesh& mesh, int exponent, const std::vector<PieceFile>& files, RankStats& stats)
      : mesh_(mesh), exponent_(exponent), files_(files), stats_(stats) {
    MPI_Comm_size(job_comm(), &size_);
    claims_.resize(static_cast<std::size_t>(size_));
  }

  void run() {
    // 1. The order, and which rank writes which file.
    const std::string placement = serialize_placement(mesh_.bulks);  // before the order: no rank waits for it
    broadcast_text(order());
    broadcast_text(placement);
    take_claims();
    // 2. What the owners need of rank 0: the band's tets of their pieces, then their points' coordinates.
    for (int rank = 1; rank < size_; ++rank)
      for (const Claim& claim : claims_[rank]) send_band_part(rank, claim);
    for (int rank = 1; rank < size_; ++rank) answer_points(rank);
    // 3. Every rank writes its files at once; rank 0 then takes the others' answers.
    for (std::size_t i = 0; i < files_.size(); ++i)
      if (!claimed_[i]) write_own(files_[i]);
    for (int rank = 1; rank < size_; ++rank)
      for (const Claim& claim : claims_[rank]) take_answer(rank, claim);
    if (failure_) std::rethrow_exception(failure_);
  }

 private:
  std::string order() const {
    std::string order = std::string(kSpreadPiecesOrder) + '\n' + std::to_string(exponent_) + '\n';
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

  void send_band_part(int rank, const Claim& claim) {
    std::vector<Tet> tets;
    std::vector<std::int32_t> solid;
    try {
      if (!claim.valid) throw InternalError("no band part for a piece file claimed wrongly");
      band_tets_of(mesh_, files_[claim.file].piece, tets, solid);
    } catch (...) {  // (out of memory) the rank is still told, so it does not wait
      fail(std::current_exception());
      send_to(rank, "N", kWorkerSeconds);
      return;
    }
    send_to(rank, "B", kWorkerSeconds);
    send_to(rank, bytes_of(run_of(tets)), kWorkerSeconds);
    send_to(rank, bytes_of(run_of(solid)), kWorkerSeconds);
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
  void write_own(const PieceFile& file) {
    if (failure_) return;
    try {
      const SpreadBulk* bulk = file.piece < 0 ? nullptr : bulk_of(file.piece);
      if (bulk && !bulk->here && bulk->tets > 0)
        throw InternalError("no rank wrote the piece file of piece " + std::to_string(file.piece));
      std::vector<std::int32_t> bulk_solid, bulk_piece;
      const TetBlock* tets = bulk && bulk->here ? &bulk->block : nullptr;
      if (tets) bulk_columns(*tets, *bulk, bulk_solid, bulk_piece);
      std::vector<Tet> band;
      std::vector<std::int32_t> band_solid;
      band_tets_of(mesh_, file.piece, band, band_solid);
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
      write_piece_file(MeshFormat::pvtu, PieceArrays(arrays.begin(), arrays.end()), file.temporary, file.shown);
      ++stats_.piece_files_written;
    } catch (...) {
      fail(std::current_exception());
    }
  }

  const SpreadMesh& mesh_;
  int exponent_ = 0;
  const std::vector<PieceFile>& files_;
  RankStats& stats_;
  int size_ = 1;
  std::vector<std::vector<Claim>> claims_;  // per rank: the files it writes
  std::vector<bool> claimed_;               // per file: another rank writes it
  std::exception_ptr failure_;
};

// ---------------------------------------------------------------------------------------------
// The other ranks

struct OwnFile {
  PieceFile file;
  TetBlock* bulk = nullptr;
  const SpreadBulk* place = nullptr;
  std::vector<Tet> band;
  std::vector<std::int32_t> band_solid;
  bool received = false;
};

// Its band part as rank 0 sent it ("B", tets, solids; or "N").
void receive_band_part(OwnFile& own) {
  if (receive_from(0, kRootSeconds) != "B") return;
  const std::optional<std::vector<Tet>> tets = values_of<Tet>(receive_from(0, kRootSeconds));
  const std::optional<std::vector<std::int32_t>> solid = values_of<std::int32_t>(receive_from(0, kRootSeconds));
  if (!tets || !solid || tets->size() != solid->size()) return;
  own.band = *tets, own.band_solid = *solid;
  own.received = !test_hooks::block_lost(my_rank());
}

// The points the files use that this rank does not keep (outside its bulks' Steiner rows), ascending.
std::vector<std::int64_t> points_asked(const std::vector<OwnFile>& files) {
  std::vector<std::int64_t> asked;
  const auto add = [&](const std::vector<Tet>& tets, const SpreadBulk& place) {
    for (const Tet& t : tets)
      for (std::int32_t v : t)
        if (v < place.first_point || v >= place.first_point + place.points) asked.push_back(v);
  };
  for (const OwnFile& own : files) add(own.bulk->tets, *own.place), add(own.band, *own.place);
  std::sort(asked.begin(), asked.end());
  asked.erase(std::unique(asked.begin(), asked.end()), asked.end());
  return asked;
}

// Writes one file (or sends its arrays to rank 0 when this rank cannot open its temporary) and
// answers for it.
void write_one(OwnFile& own, const std::vector<std::int64_t>& asked, const std::vector<double>& xyz, RankStats& stats) {
  try {
    if (!own.received)
      throw OutputError("rank " + std::to_string(my_rank()) + " did not receive the content of '" + own.file.shown +
                        "'");
    if (static_cast<std::int64_t>(own.bulk->steiner_points.size()) != own.place->points)
      throw InternalError("the bulk of piece " + std::to_string(own.place->piece) + " does not match its placement");
    std::vector<std::int32_t> solid, piece;
    bulk_columns(*own.bulk, *own.place, solid, piece);
    VtuCells cells = cells_of(own.file.piece, own.bulk, solid, own.band, own.band_solid);
    const SpreadBulk& place = *own.place;
    for (std::int64_t id : cells.global_ids) {
      const double* p = nullptr;
      if (id >= place.first_point && id < place.first_point + place.points) {
        p = own.bulk->steiner_points[id - place.first_point].data();
      } else {
        const auto at = std::lower_bound(asked.begin(), asked.end(), id);
        if (at == asked.end() || *at != id) throw InternalError("a piece file's point was not asked for");
        p = xyz.data() + 3 * (at - asked.begin());
      }
      cells.xyz.insert(cells.xyz.end(), p, p + 3);
    }
    const int fd = ::open(own.file.temporary.c_str(), O_WRONLY | O_CLOEXEC);  // never creates it
    if (fd < 0) {
      const PieceArrays arrays = arrays_of(cells.view());
      send_to(0, "A" + std::to_string(arrays.size()), kRootSeconds);
      for (std::string_view bytes : arrays) send_to(0, bytes, kRootSeconds);
      return;
    }
    ::close(fd);
    write_vtu_file(cells.view(), own.file.temporary, own.file.shown);
    ++stats.piece_files_written;
  } catch (const std::exception& e) {
    send_to(0, std::string("E") + e.what(), kRootSeconds);
    return;
  }
  send_to(0, "", kRootSeconds);
}

}  // namespace

void write_spread_piece_files(const SpreadMesh& mesh, int exponent, const std::vector<PieceFile>& files,
                              RankStats& stats) {
  SpreadPieceFileWrite(mesh, exponent, files, stats).run();
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

void write_own_piece_files(std::istringstream& order, BulksForWrites& kept, RankStats& stats) {
  std::string exponent, piece, temporary, shown;
  std::getline(order, exponent);
  std::vector<PieceFile> files;
  while (std::getline(order, piece, '\0') && std::getline(order, temporary, '\0') && std::getline(order, shown, '\0'))
    files.push_back({std::stoi(piece), temporary, shown});
  const std::string placement = broadcast_text("");
  // 1. The files of the bulks this rank keeps.
  std::vector<SpreadBulk> places;
  std::vector<OwnFile> own;
  std::vector<std::int64_t> claims;
  try {
    places = deserialize_placement(placement);
    std::map<int, TetBlock>& bulks = kept.get(std::stoi(exponent));
    for (std::size_t i = 0; i < files.size(); ++i) {
      const auto bulk = bulks.find(files[i].piece);
      const auto place =
          std::find_if(places.begin(), places.end(), [&](const SpreadBulk& p) { return p.piece == files[i].piece; });
      if (bulk == bulks.end() || place == places.end()) continue;
      own.push_back({files[i], &bulk->second, &*place, {}, {}, false});
      claims.push_back(static_cast<std::int64_t>(i));
    }
  } catch (const std::exception& e) {  // rank 0 finds files nobody claims and fails
    log::error(e.what());
    own.clear(), claims.clear();
  }
  send_to(0, bytes_of(run_of(claims)), kRootSeconds);
  // 2. The band's parts, then the coordinates of the points this rank lacks.
  for (OwnFile& file : own) receive_band_part(file);
  const std::vector<std::int64_t> asked = points_asked(own);
  std::string request = "I";
  request.append(bytes_of(run_of(asked)));
  send_to(0, request, kRootSeconds);
  const std::optional<std::vector<double>> xyz = values_of<double>(receive_from(0, kRootSeconds));
  const bool have_points = xyz && xyz->size() == 3 * asked.size();
  // 3. The files.
  for (OwnFile& file : own) {
    if (!have_points) file.received = false;
    write_one(file, asked, have_points ? *xyz : std::vector<double>{}, stats);
  }
}

}  // namespace partet::mpi
