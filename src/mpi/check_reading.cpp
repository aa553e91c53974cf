#include "mpi/check_reading.hpp"

#include <algorithm>
#include <climits>

#include "io/mesh_read.hpp"
#include "io/read_surface.hpp"
#include "io/tetgen_files.hpp"
#include "partet/errors.hpp"
#include "stages/check.hpp"
#include "stages/validate.hpp"

namespace partet::distributed {

InputFigures read_input(MPI_Comm comm, int rank, const std::string& path) {
  InputFigures input;
  throw_if_any(comm, rank == 0 ? error_of(path, [&] { input.surface = read_surface(path); }) : "");
  long double figures[2] = {0, 0};  // enclosed volume, Euler characteristic
  if (rank == 0)
    figures[0] = enclosed_volume_precise(input.surface), figures[1] = surface_euler_characteristic(input.surface);
  MPI_Bcast(figures, 2, MPI_LONG_DOUBLE, 0, comm);
  input.volume = figures[0], input.euler = figures[1];
  return input;
}

namespace {

// Rank 0's lines, on every rank.
std::vector<std::string> broadcast_lines(MPI_Comm comm, const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += line + '\n';
  std::uint64_t length = text.size();
  MPI_Bcast(&length, 1, MPI_UINT64_T, 0, comm);
  text.resize(length);
  MPI_Bcast(text.data(), static_cast<int>(length), MPI_CHAR, 0, comm);
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

// Rows to the owners of their ids (each rank the run of [0, total) the XDMF check's ranks read)
// and returned in id order: every id in [0, total) given, once or (same_values) with the same
// values each time; otherwise every rank throws InputError naming `file` (the lowest rank's find).
template <class Values>
std::vector<Values> place_rows(const Part& part, std::vector<Id>&& ids, std::vector<Values>&& values,
                               std::uint64_t total, Repeats repeats, const std::string& file) {
  // `file` names a TetGen file, or a set of MSH or VTK files ("the set of 'PATH'"), whose rows are points by id.
  std::vector<std::vector<Row<Values>>> outgoing(part.size);
  std::string error;
  for (std::size_t i = 0; i < ids.size() && error.empty(); ++i) {
    if (ids[i] < 0 || static_cast<std::uint64_t>(ids[i]) >= total)
      error = file + " has index " + std::to_string(ids[i]) + ", beyond its " + std::to_string(total) + " rows";
    else
      outgoing[run_owner(ids[i], total, part.size)].push_back({ids[i], values[i]});
  }
  throw_if_any(part.comm, error);
  std::vector<Id>().swap(ids);
  std::vector<Values>().swap(values);
  std::vector<Row<Values>> here = all_to_all(part.comm, std::move(outgoing));
  std::sort(here.begin(), here.end(), [](const Row<Values>& a, const Row<Values>& b) { return a.id < b.id; });
  const auto [first, last] = run_of(total, part.rank, part.size);
  std::vector<Values> placed(last - first);
  std::uint64_t expected = first;
  for (std::size_t i = 0; i < here.size() && error.empty(); ++i) {
    const std::uint64_t id = static_cast<std::uint64_t>(here[i].id);
    if (i > 0 && here[i - 1].id == here[i].id) {
      if (repeats == Repeats::refused)
        error = file + " has index " + std::to_string(id) + " twice";
      else if (here[i - 1].values != here[i].values)
        error = "two files of " + file + " give node " + std::to_string(id + 1) + " other coordinates";
      continue;
    }
    if (id != expected) break;
    placed[id - first] = here[i].values, ++expected;
  }
  if (error.empty() && expected != last)
    error = repeats == Repeats::refused ? file + " has no row of index " + std::to_string(expected)
                                        : "no file of " + file + " gives node " + std::to_string(expected + 1) +
                                              " (the nodes must be numbered from 1 to the highest without a gap)";
  throw_if_any(part.comm, error);
  return placed;
}

// The set's points: ids from 0 to the highest, a point in several files the same in each.
void place_set_points(Part& part, MeshPart& mine, const std::string& path) {
  std::int64_t highest = -1;
  for (Id id : mine.node_ids) highest = std::max(highest, id);
  MPI_Allreduce(MPI_IN_PLACE, &highest, 1, MPI_INT64_T, MPI_MAX, part.comm);
  part.totals.points = static_cast<std::uint64_t>(highest + 1);
  part.block.points = place_rows(part, std::move(mine.node_ids), std::move(mine.nodes), part.totals.points,
                                 Repeats::same_values, "the set of '" + path + "'");
}

// ---------------------------------------------------------------------------------------------
// A set of TetGen files, each read in parts: rank r reads the r-th share of every file's bytes

// This rank's rows of one file of the set, and the file's layout.
TetgenRowsRead read_tetgen_part(const Part& part, const std::string& path, TetgenFile file, TetgenFileLayout& layout) {
  TetgenRowsRead rows;
  throw_if_any(part.comm, error_of(path, [&] {
                 layout = tetgen_file_layout(path, file);
                 rows = read_tetgen_rows(path, file, tetgen_part_begin(path, layout, part.rank, part.size),
                                         tetgen_part_begin(path, layout, part.rank + 1, part.size));
               }));
  return rows;
}

// The file's numbering base (0 or 1, as TetGen allows): its first row's index. Rows out of order
// are found when they are placed.
std::int64_t numbering_base(const Part& part, const TetgenRowsRead& rows, const std::string& path) {
  std::int64_t first = rows.index.empty() ? INT64_MAX : rows.index.front();
  MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT64_T, MPI_MIN, part.comm);
  if (first == INT64_MAX) return 0;  // no rows
  if (first != 0 && first != 1)
    throw InputError(path + ": first index must be 0 or 1, found " + std::to_string(first));  // on every rank
  return first;
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

// The set's ID: every file's "# partet mesh ID" line (found by whichever rank reads the file's
// end) must be there and the same. Without one the set is not partet's, and its .face file
// does not promise outward faces: that is for the check in one process.
std::string check_set_id(const std::vector<std::pair<std::string, std::string>>& ids) {
  for (const auto& [file, id] : ids)
    if (id.empty())
      throw InputError(file +
                       " has no '# partet mesh ID' line: only sets partet wrote are checked on several ranks; "
                       "check this one in one process");
  return set_id_violation(ids);
}

// One file of a TetGen set: its layout, its numbering base and this rank's rows. Its set ID is
// added to `ids`.
struct FileShare {
  TetgenFileLayout layout;
  std::int64_t base = 0;
  TetgenRowsRead rows;
};

FileShare read_share(const Part& part, const std::string& prefix, TetgenFile file,
                     std::vector<std::pair<std::string, std::string>>& ids) {
  const std::string path = prefix + extension(file);
  FileShare share;
  share.rows = read_tetgen_part(part, path, file, share.layout);
  share.base = numbering_base(part, share.rows, path);
  ids.push_back({path, first_nonempty(part.comm, share.rows.id)});
  return share;
}

// place_points and place_tets free the rows they place (the layout and base stay).
void place_points(Part& part, FileShare& node, const std::string& prefix) {
  part.totals.points = static_cast<std::uint64_t>(node.layout.count);
  part.block.points = place_rows(part, row_ids(node.rows.index, node.base), std::move(node.rows.points),
                                 part.totals.points, Repeats::refused, prefix + ".node");
  node.rows = {};
}

void place_tets(Part& part, FileShare& ele, std::int64_t vertex_base, const std::string& prefix) {
  part.totals.tets = static_cast<std::uint64_t>(ele.layout.count);
  part.block.tets =
      place_rows(part, row_ids(ele.rows.index, ele.base), rows_of_ids<4>(ele.rows.values, vertex_base, false),
                 part.totals.tets, Repeats::refused, prefix + ".ele");
  ele.rows = {};
}

// The .face rows stay where they were read.
void keep_faces(Part& part, FileShare&& face, std::int64_t vertex_base, const std::string& prefix) {
  part.block.faces = rows_of_ids<3>(face.rows.values, vertex_base, false);
  part.block.face_marker = std::move(face.rows.markers);
  std::uint64_t faces = part.block.faces.size();
  MPI_Allreduce(MPI_IN_PLACE, &faces, 1, MPI_UINT64_T, MPI_SUM, part.comm);
  if (faces != static_cast<std::uint64_t>(face.layout.count))
    throw InputError(prefix + ".face declares " + std::to_string(face.layout.count) + " faces but has " +
                     std::to_string(faces) + " rows");  // on every rank
  part.totals.faces = faces;
}

// The .neigh rows of this rank's tets, numbered as the .ele rows are.
std::vector<std::array<Id, 4>> place_neighbours(const Part& part, const FileShare& neigh, const FileShare& ele,
                                                const std::string& prefix) {
  if (neigh.layout.count != ele.layout.count)
    throw InputError(prefix + ".neigh: " + std::to_string(neigh.layout.count) + " neighbour rows for " +
                     std::to_string(ele.layout.count) + " tetrahedra");  // on every rank
  return place_rows(part, row_ids(neigh.rows.index, ele.base), rows_of_ids<4>(neigh.rows.values, ele.base, true),
                    part.totals.tets, Repeats::refused, prefix + ".neigh");
}

}  // namespace

void read_mesh_part(Part& part, const std::string& path) {
  MeshPart mine = read_files_share(part, path);
  place_set_points(part, mine, path);
  part.block.tets = std::move(mine.tets);
  part.block.faces = std::move(mine.triangles);
  part.block.face_marker = std::move(mine.markers);
  std::uint64_t counts[2] = {part.block.tets.size(), part.block.faces.size()};
  MPI_Allreduce(MPI_IN_PLACE, counts, 2, MPI_UINT64_T, MPI_SUM, part.comm);
  part.totals.tets = counts[0], part.totals.faces = counts[1];
}

TetgenExtras read_tetgen_parts(Part& part, const std::string& prefix) {
  std::vector<std::pair<std::string, std::string>> ids;  // each file's set ID
  FileShare node = read_share(part, prefix, TetgenFile::node, ids);
  place_points(part, node, prefix);
  FileShare ele = read_share(part, prefix, TetgenFile::ele, ids);
  place_tets(part, ele, node.base, prefix);
  keep_faces(part, read_share(part, prefix, TetgenFile::face, ids), node.base, prefix);
  TetgenExtras extras;
  extras.neighbours = place_neighbours(part, read_share(part, prefix, TetgenFile::neigh, ids), ele, prefix);
  extras.set_violation = check_set_id(ids);
  return extras;
}

}  // namespace partet::distributed
