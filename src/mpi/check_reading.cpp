#include "mpi/check_reading.hpp"

#include <algorithm>
#include <climits>
#include <cmath>

#include "common/test_hooks.hpp"
#include "io/mesh_read.hpp"
#include "io/read_surface.hpp"
#include "io/tetgen_files.hpp"
#include "partet/errors.hpp"
#include "stages/check.hpp"
#include "stages/validate.hpp"

namespace partet::distributed {

namespace {

void add_figures(MPI_Comm comm, int rank, InputFigures& input) {
  long double figures[2] = {0, 0};  // enclosed volume, Euler characteristic
  if (rank == 0)
    figures[0] = enclosed_volume_precise(input.surface()), figures[1] = surface_euler_characteristic(input.surface());
  broadcast_from(figures, 2, MPI_LONG_DOUBLE, 0, comm);
  input.volume = figures[0], input.euler = figures[1];
}

}  // namespace

InputFigures read_input(MPI_Comm comm, int rank, const std::string& path) {
  InputFigures input;
  throw_if_any(comm, rank == 0 ? error_of(path, [&] { input.read = read_surface(path); }) : "");
  add_figures(comm, rank, input);
  return input;
}

InputFigures held_input(MPI_Comm comm, int rank, const SurfaceMesh* held) {
  InputFigures input;
  input.held = held;
  throw_if_any(comm, rank == 0 && !held ? "rank 0 holds no input to check the mesh against" : "");
  add_figures(comm, rank, input);
  return input;
}

namespace {

// Rank 0's lines, on every rank.
std::vector<std::string> broadcast_lines(MPI_Comm comm, const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += line + '\n';
  std::uint64_t length = text.size();
  broadcast_from(&length, 1, MPI_UINT64_T, 0, comm);
  text.resize(length);
  broadcast_from(text.data(), static_cast<int>(length), MPI_CHAR, 0, comm);
  std::vector<std::string> out;
  for (std::size_t at = 0, end; (end = text.find('\n', at)) != std::string::npos; at = end + 1)
    out.push_back(text.substr(at, end - at));
  return out;
}

// This rank's files of a set named by one path (mesh_read.hpp): rank 0 reads the named one, which
// lists the set; file i of the set is rank (i mod size)'s.
MeshPart read_files_share(const Part& part, const std::string& path) {
  MeshPart mine;
  std::vector<std::string> files;
  throw_if_any(part.comm, part.rank == 0 ? error_of(path, [&] { files = read_named_mesh_file(path, mine); }) : "");
  files = broadcast_lines(part.comm, files);
  std::string error;
  for (std::size_t i = 1; i < files.size() && error.empty(); ++i)
    if (static_cast<int>(i % static_cast<std::size_t>(part.size)) == part.rank)
      error = error_of(files[i], [&] { read_set_file(path, files[i], mine); });
  throw_if_any(part.comm, error);
  return mine;
}

// A row of a file with its id: a point, or a tet's vertices or neighbours.
template <class Values>
struct Row {
  Id id;
  Values values;
};

// How a row given twice is taken: the same point in several files of a set (MSH, .pvtu), or a TetGen
// file's index, which must be unique.
enum class Repeats { same_values, refused };

// Rows to the owners of their ids (each rank the run of [0, total) the XDMF check's ranks read),
// in rounds: each round every rank sends the rows it has read since the last and places those it
// receives, so that besides its placed rows a rank holds one round's. At the end every id in
// [0, total) must have been given, once or (same_values) with the same values each time;
// otherwise every rank throws InputError naming `file` (the lowest rank's find). `file` names a
// TetGen file, or a set of MSH or VTK files ("the set of 'PATH'"), whose rows are points by id.
template <class Values>
class RowPlacer {
 public:
  RowPlacer(const Part& part, std::uint64_t total, Repeats repeats, std::string file)
      : part_(part), total_(total), repeats_(repeats), file_(std::move(file)) {
    const auto [first, last] = run_of(total, part.rank, part.size);
    first_ = first;
    placed_.resize(last - first);
    seen_.assign(last - first, 0);
  }

  // Collective: one round; ids[i] is the id of values[i] (both freed here).
  void add(std::vector<Id>&& ids, std::vector<Values>&& values) {
    std::vector<std::vector<Row<Values>>> outgoing(part_.size);
    for (std::size_t i = 0; i < ids.size() && error_.empty(); ++i) {
      if (ids[i] < 0 || static_cast<std::uint64_t>(ids[i]) >= total_)
        error_ = file_ + " has index " + std::to_string(ids[i]) + ", beyond its " + std::to_string(total_) + " rows";
      else
        outgoing[run_owner(ids[i], total_, part_.size)].push_back({ids[i], values[i]});
    }
    std::vector<Id>().swap(ids);
    std::vector<Values>().swap(values);
    for (const Row<Values>& row : all_to_all(part_.comm, std::move(outgoing))) place(row);
  }

  // Collective: the rows of this rank's run, in id order.
  std::vector<Values> finish() {
    if (error_.empty()) {
      const auto missing = std::find(seen_.begin(), seen_.end(), 0);
      if (missing != seen_.end()) {
        const std::uint64_t id = first_ + static_cast<std::uint64_t>(missing - seen_.begin());
        error_ = repeats_ == Repeats::refused ? file_ + " has no row of index " + std::to_string(id)
                                              : "no file of " + file_ + " gives node " + std::to_string(id + 1) +
                                                    " (the nodes must be numbered from 1 to the highest without a gap)";
      }
    }
    throw_if_any(part_.comm, error_);
    std::vector<char>().swap(seen_);
    return std::move(placed_);
  }

 private:
  void place(const Row<Values>& row) {
    const auto at = static_cast<std::size_t>(static_cast<std::uint64_t>(row.id) - first_);
    if (!seen_[at]) {
      placed_[at] = row.values, seen_[at] = 1;
    } else if (error_.empty()) {
      if (repeats_ == Repeats::refused)
        error_ = file_ + " has index " + std::to_string(row.id) + " twice";
      else if (placed_[at] != row.values)
        error_ = "two files of " + file_ + " give node " + std::to_string(row.id + 1) + " other coordinates";
    }
  }

  const Part& part_;
  std::uint64_t total_, first_ = 0;
  Repeats repeats_;
  std::string file_, error_;
  std::vector<Values> placed_;
  std::vector<char> seen_;  // per row of this rank's run: placed
};

// All rows in one round.
template <class Values>
std::vector<Values> place_rows(const Part& part, std::vector<Id>&& ids, std::vector<Values>&& values,
                               std::uint64_t total, Repeats repeats, const std::string& file) {
  RowPlacer<Values> placer(part, total, repeats, file);
  placer.add(std::move(ids), std::move(values));
  return placer.finish();
}

// The set's points: ids from 0 to the highest, a point in several files the same in each.
void place_set_points(Part& part, MeshPart& mine, const std::string& path) {
  std::int64_t highest = -1;
  for (Id id : mine.node_ids) highest = std::max(highest, id);
  reduce_in_place(&highest, 1, MPI_INT64_T, MPI_MAX, part.comm);
  part.totals.points = static_cast<std::uint64_t>(highest + 1);
  part.block.points = place_rows(part, std::move(mine.node_ids), std::move(mine.nodes), part.totals.points,
                                 Repeats::same_values, "the set of '" + path + "'");
}

// ---------------------------------------------------------------------------------------------
// A set of TetGen files, each read in parts: rank r reads the r-th share of every file's bytes,
// in rounds of about 64 MB of text, each round's rows placed before the next is read

// One file of a TetGen set: its layout and numbering base (0 or 1, as TetGen allows: its first
// row's index; rows out of order are found when they are placed), agreed by every rank.
struct TetgenFileShare {
  std::string path;
  TetgenFileLayout layout;
  std::int64_t base = 0;
};

TetgenFileShare file_share(const Part& part, const std::string& prefix, TetgenFile file, const std::string& suffix) {
  TetgenFileShare share{prefix + extension(file) + suffix, {}, 0};
  throw_if_any(part.comm, error_of(share.path, [&] {
                 share.layout = tetgen_file_layout(share.path, file);
                 share.base = share.layout.first_index;
                 if (share.layout.count > 0 && share.base != 0 && share.base != 1)
                   throw InputError(share.path + ": first index must be 0 or 1, found " + std::to_string(share.base));
               }));
  return share;
}

// Reads this rank's share of the file in rounds (every rank as many), handing each round's rows
// to take (collective: every rank calls it in every round). Returns the set ID, when this rank's
// share holds the file's "# partet mesh ID" line.
template <class Take>
std::string read_in_rounds(const Part& part, const TetgenFileShare& share, TetgenFile file, const Take& take) {
  const double round_bytes = test_hooks::check_pass_bytes(64 << 20);
  const std::uint64_t text = share.layout.size - share.layout.rows_begin;
  const auto rounds = static_cast<int>(std::max<std::uint64_t>(
      1, static_cast<std::uint64_t>(std::ceil(static_cast<double>(text) / part.size / std::max(round_bytes, 1.0)))));
  std::string id;
  for (int round = 0; round < rounds; ++round) {
    TetgenRowsRead rows;
    const int piece = part.rank * rounds + round, pieces = part.size * rounds;
    throw_if_any(part.comm, error_of(share.path, [&] {
                   rows = read_tetgen_rows(share.path, file, tetgen_part_begin(share.path, share.layout, piece, pieces),
                                           tetgen_part_begin(share.path, share.layout, piece + 1, pieces));
                 }));
    if (!rows.id.empty()) id = rows.id;
    take(rows);
  }
  return id;
}

// The ids of rows (their index less the base), and each row's values as 0-based ids; -1 stays
// -1 (a neighbour row's "none").
std::vector<Id> row_ids(const std::vector<std::int64_t>& index, std::int64_t base) {
  std::vector<Id> ids(index.size());
  for (std::size_t i = 0; i < index.size(); ++i) ids[i] = index[i] - base;
  return ids;
}

template <std::size_t N>
std::vector<std::array<Id, N>> rows_of_ids(const std::vector<std::int64_t>& values, std::int64_t base,
                                           bool keep_minus_one) {
  std::vector<std::array<Id, N>> rows(values.size() / N);
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t k = 0; k < N; ++k) {
      const std::int64_t v = values[N * i + k];
      rows[i][k] = keep_minus_one && v == -1 ? -1 : v - base;
    }
  return rows;
}

// Set IDs of the files read so far, as (file, ID).
using SetIds = std::vector<std::pair<std::string, std::string>>;

// The set's ID: every file's "# partet mesh ID" line (found by whichever rank reads the file's
// end) must be there and the same. Without one the set is not partet's, and its .face file
// does not promise outward faces: that is for the check in one process.
std::string check_set_id(const SetIds& ids) {
  for (const auto& [file, id] : ids)
    if (id.empty())
      throw InputError(file +
                       " has no '# partet mesh ID' line: only sets partet wrote are checked on several ranks; "
                       "check this one in one process");
  return set_id_violation(ids);
}

// A file whose rows go to the owners of their index: .node (points), .ele (tets), .neigh (a tet's
// neighbours); a row's id is its index less index_base (the .ele rows' base for .neigh, whose rows
// are tets), and convert gives its values. The rows arrive in id order on their owners.
template <class Values, class Convert>
std::vector<Values> place_file(const Part& part, const TetgenFileShare& share, TetgenFile file, std::int64_t index_base,
                               Convert convert, SetIds& ids) {
  RowPlacer<Values> placer(part, static_cast<std::uint64_t>(share.layout.count), Repeats::refused, share.path);
  const std::string id = read_in_rounds(
      part, share, file, [&](TetgenRowsRead& rows) { placer.add(row_ids(rows.index, index_base), convert(rows)); });
  ids.push_back({share.path, first_nonempty(part.comm, id)});
  return placer.finish();
}

// The .face rows stay where they were read.
void keep_faces(Part& part, const TetgenFileShare& face, std::int64_t vertex_base, SetIds& ids) {
  const std::string id = read_in_rounds(part, face, TetgenFile::face, [&](TetgenRowsRead& rows) {
    const std::vector<std::array<Id, 3>> faces = rows_of_ids<3>(rows.values, vertex_base, false);
    part.block.faces.insert(part.block.faces.end(), faces.begin(), faces.end());
    part.block.face_marker.insert(part.block.face_marker.end(), rows.markers.begin(), rows.markers.end());
  });
  ids.push_back({face.path, first_nonempty(part.comm, id)});
  std::uint64_t faces = part.block.faces.size();
  reduce_in_place(&faces, 1, MPI_UINT64_T, MPI_SUM, part.comm);
  if (faces != static_cast<std::uint64_t>(face.layout.count))
    throw InputError(face.path + " declares " + std::to_string(face.layout.count) + " faces but has " +
                     std::to_string(faces) + " rows");  // on every rank
  part.totals.faces = faces;
}

}  // namespace

void read_mesh_part(Part& part, const std::string& path) {
  MeshPart mine = read_files_share(part, path);
  place_set_points(part, mine, path);
  part.block.tets = std::move(mine.tets);
  part.block.faces = std::move(mine.triangles);
  part.block.face_marker = std::move(mine.markers);
  std::uint64_t counts[2] = {part.block.tets.size(), part.block.faces.size()};
  reduce_in_place(counts, 2, MPI_UINT64_T, MPI_SUM, part.comm);
  part.totals.tets = counts[0], part.totals.faces = counts[1];
}

TetgenExtras read_tetgen_parts(Part& part, const std::string& prefix, const std::string& suffix) {
  SetIds ids;
  const TetgenFileShare node = file_share(part, prefix, TetgenFile::node, suffix);
  part.totals.points = static_cast<std::uint64_t>(node.layout.count);
  part.block.points = place_file<Point3>(
      part, node, TetgenFile::node, node.base, [](TetgenRowsRead& rows) { return std::move(rows.points); }, ids);
  const TetgenFileShare ele = file_share(part, prefix, TetgenFile::ele, suffix);
  part.totals.tets = static_cast<std::uint64_t>(ele.layout.count);
  part.block.tets = place_file<std::array<Id, 4>>(
      part, ele, TetgenFile::ele, ele.base,
      [&](TetgenRowsRead& rows) { return rows_of_ids<4>(rows.values, node.base, false); }, ids);
  keep_faces(part, file_share(part, prefix, TetgenFile::face, suffix), node.base, ids);
  const TetgenFileShare neigh = file_share(part, prefix, TetgenFile::neigh, suffix);
  if (neigh.layout.count != ele.layout.count)
    throw InputError(neigh.path + ": " + std::to_string(neigh.layout.count) + " neighbour rows for " +
                     std::to_string(ele.layout.count) + " tetrahedra");  // on every rank
  // The neighbours' rows are tets, numbered as the .ele rows are.
  TetgenExtras extras;
  extras.neighbours = place_file<std::array<Id, 4>>(
      part, neigh, TetgenFile::neigh, ele.base,
      [&](TetgenRowsRead& rows) { return rows_of_ids<4>(rows.values, ele.base, true); }, ids);
  extras.set_violation = check_set_id(ids);
  return extras;
}

}  // namespace partet::distributed
