#include "mpi/spread_row_files.hpp"

#include <algorithm>
#include <cstring>
#include <exception>
#include <map>
#include <vector>

#include "common/log.hpp"
#include "common/test_hooks.hpp"
#include "io/buffered_file.hpp"
#include "io/row_lines.hpp"
#include "io/tetgen_files.hpp"
#include "mpi/spread_row_order.hpp"
#include "mpi/write_messages.hpp"
#include "partet/errors.hpp"
#include "runner/serialize.hpp"

namespace partet::mpi {
namespace {

class SpreadRowsWrite {
 public:
  SpreadRowsWrite(MeshFormat format, const SpreadMesh& mesh, const MeshOutput& output, int exponent,
                  const TetgenLines& face_lines)
      : format_(format), mesh_(mesh), output_(output), exponent_(exponent), face_lines_(face_lines) {
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
    // 3. TetGen's .face: rank 0 keeps every row, and every rank formats its share of them at once
    //    (the ranks keeping bulks had the most of the .ele and .neigh rows).
    if (format_ == MeshFormat::tetgen) add_face_file(set, prefix);
  }

 private:
  // A run of rows: a bulk's, or (bulk null) rank 0's own points (the split surface's, then those
  // healing added) or the band's tets; of those, rows [from, from + count), formatted by rank
  // given_to (another rank formats a share of the split surface's points for rank 0).
  struct RowRun {
    std::int64_t first = 0, count = 0;
    const SpreadBulk* bulk = nullptr;
    std::int64_t from = 0;
    int given_to = 0;
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
    id_ = mesh_id(fingerprint(true), fingerprint(false), fingerprint_rows(TetgenFile::face, output_.boundary));
    for (TetgenFile file : {TetgenFile::node, TetgenFile::ele, TetgenFile::neigh}) {
      const std::string shown = prefix + extension(file);
      const std::size_t count = static_cast<std::size_t>(file == TetgenFile::node ? mesh_.points : mesh_.tets);
      const RowLines lines = file == TetgenFile::node  ? RowLines::tetgen_node
                             : file == TetgenFile::ele ? RowLines::tetgen_ele
                                                       : RowLines::tetgen_neigh;
      set.add(shown, [&](const std::string& temporary) {
        write_tetgen_file(
            file, count, id_, temporary, shown, [&](BufferedFile& out) { write_runs(out, lines, 0); },
            Closing::in_background);
      });
    }
  }

  void add_face_file(OutputSet& set, const std::string& prefix) const {
    const std::string shown = prefix + extension(TetgenFile::face);
    const TetgenRows rows{TetgenFile::face, bytes_of(run_of(output_.boundary)).data(), output_.boundary.size(),
                          output_.split_from};
    set.add(shown, [&](const std::string& temporary) {
      write_tetgen_file(rows, face_lines_, id_, temporary, shown, Closing::in_background);
    });
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

  // The rank that formats a run's rows.
  int formatter(const RowRun& run) const { return elsewhere(run) ? claims_.at(run.bulk->piece).rank : run.given_to; }

  // The runs of a section, the split surface's points dealt out so that every rank formats about
  // as many rows as the others: they are most of a points section's rows, and rank 0 keeps them
  // all (the other ranks keep bulks, with few points of their own).
  std::vector<RowRun> dealt_runs(bool points) const {
    std::vector<RowRun> runs = runs_of(points);
    const auto split = std::find_if(runs.begin(), runs.end(), [](const RowRun& r) { return !r.bulk && r.first == 0; });
    if (!points || size_ == 1 || split == runs.end()) return runs;
    std::vector<std::size_t> kept(static_cast<std::size_t>(size_), 0);
    for (const RowRun& run : runs)
      if (&run != &*split) kept[static_cast<std::size_t>(formatter(run))] += static_cast<std::size_t>(run.count);
    const std::vector<std::size_t> shares = point_shares(static_cast<std::size_t>(split->count), kept);
    std::vector<RowRun> dealt;
    for (std::size_t rank = 0, from = 0; rank < shares.size(); from += shares[rank], ++rank)
      if (shares[rank] > 0) {
        const auto at = static_cast<std::int64_t>(from);
        dealt.push_back({at, static_cast<std::int64_t>(shares[rank]), nullptr, at, static_cast<int>(rank)});
      }
    const auto at = runs.erase(split);
    runs.insert(at, dealt.begin(), dealt.end());
    return runs;
  }

  // Rank 0's own rows of a run.
  const std::vector<Point3>& own_points(const RowRun& run) const {
    if (run.bulk) return run.bulk->block.steiner_points;
    return run.first < static_cast<std::int64_t>(mesh_.split_points.size()) ? mesh_.split_points : mesh_.healing_points;
  }
  const std::vector<Tet>& own_tets(const RowRun& run) const {
    return run.bulk ? run.bulk->block.tets : mesh_.band_tets;
  }
  // The mesh's id of each of their ids.
  PointIds own_ids(const RowRun& run) const { return run.bulk ? run.bulk->block.ids : mesh_.band_ids(); }

  // The fingerprint of all point (or tet) rows, from every run in row order.
  RowsFingerprint fingerprint(bool points) const {
    RowsFingerprint all;
    for (const RowRun& run : runs_of(points)) {
      if (elsewhere(run)) {
        const Claim& claim = claims_.at(run.bulk->piece);
        all = combine(all, points ? claim.points : claim.tets);
      } else {
        all = combine(all, points ? fingerprint_rows(TetgenFile::node, own_points(run))
                                  : fingerprint_tets(own_tets(run), own_ids(run)));
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
    const std::vector<RowRun> runs = dealt_runs(formats_points(lines));
    send_section_orders(lines, number_from, runs);
    std::exception_ptr failure;
    for (const RowRun& run : runs) {
      if (formatter(run) != 0) {
        take_text_chunks(out, formatter(run), failure);
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

  // Each rank's order, then what it formats from: a bulk's faces across (.neigh), rank 0's points.
  void send_section_orders(RowLines lines, std::int64_t number_from, const std::vector<RowRun>& runs) const {
    std::map<int, std::vector<const RowRun*>> by_rank;
    for (const RowRun& run : runs)
      if (formatter(run) != 0) by_rank[formatter(run)].push_back(&run);
    for (const auto& [rank, its_runs] : by_rank) {
      SectionOrder order{lines, number_from, {}};
      for (const RowRun* run : its_runs) order.pieces.push_back(run->bulk ? run->bulk->piece : kGivenPoints);
      send_to(rank, order.bytes(), kWorkerSeconds);
      if (lines == RowLines::tetgen_neigh)
        for (const RowRun* run : its_runs) send_to(rank, bytes_of(run_of(run->bulk->across)), kWorkerSeconds);
      for (const RowRun* run : its_runs) {
        if (run->bulk) continue;
        send_to(rank, {reinterpret_cast<const char*>(&run->first), sizeof run->first}, kWorkerSeconds);
        const Point3* rows = own_points(*run).data() + run->from;
        send_to(rank, {reinterpret_cast<const char*>(rows), static_cast<std::size_t>(run->count) * sizeof(Point3)},
                kWorkerSeconds);
      }
    }
  }

  template <class Out>
  void write_own_run(Out& out, RowLines lines, std::int64_t number_from, const RowRun& run) const {
    const auto count = static_cast<std::size_t>(run.count);
    if (formats_points(lines))
      return write_row_lines(out, lines, {own_points(run).data() + run.from, count, run.first, number_from});
    if (lines == RowLines::tetgen_neigh) {
      return in_chunks(count, [&](std::size_t from, std::size_t n) {
        const std::vector<NeighbourRow> rows =
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
    write_row_lines(out, lines, {own_tets(run).data(), count, run.first, number_from, region, pieces, own_ids(run)});
  }

  MeshFormat format_;
  const SpreadMesh& mesh_;
  const MeshOutput& output_;
  int exponent_ = 0;
  const TetgenLines& face_lines_;
  int size_ = 1;
  std::map<int, Claim> claims_;  // by piece: the bulks kept elsewhere
  std::string id_;               // TetGen's files: the set's ID
};

}  // namespace

void add_spread_row_files(OutputSet& set, MeshFormat format, const SpreadMesh& mesh, const MeshOutput& output,
                          const std::string& prefix, int exponent, const TetgenLines& face_lines) {
  if (mesh.band_elsewhere()) throw InternalError("a single file was asked of a band left on the ranks that healed it");
  SpreadRowsWrite(format, mesh, output, exponent, face_lines).run(set, prefix);
}

}  // namespace partet::mpi
