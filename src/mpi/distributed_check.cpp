#include "mpi/distributed_check.hpp"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstring>
#include <new>
#include <tuple>

#include "io/msh_read.hpp"
#include "io/parallel_hdf5.hpp"
#include "io/tetgen_files.hpp"
#include "io/read_surface.hpp"
#include "partet/errors.hpp"
#include "stages/check.hpp"
#include "stages/validate.hpp"

namespace partet {
namespace {

using Id = std::int64_t;

// ---------------------------------------------------------------------------------------------
// Moving records between ranks

template <class T>
MPI_Datatype record_type() {
  static MPI_Datatype type = [] {
    MPI_Datatype t;
    MPI_Type_contiguous(static_cast<int>(sizeof(T)), MPI_BYTE, &t);
    MPI_Type_commit(&t);
    return t;
  }();
  return type;
}

// Sends outgoing[r] to rank r (each bucket freed as it is packed); returns what every rank sent
// here, in rank order, and how many came from each (from_counts, if given).
template <class T>
std::vector<T> all_to_all(MPI_Comm comm, std::vector<std::vector<T>>&& outgoing, std::vector<int>* from_counts = nullptr) {
  const int size = static_cast<int>(outgoing.size());
  std::vector<int> send_counts(size), receive_counts(size), send_at(size, 0), receive_at(size, 0);
  std::size_t sending = 0;
  for (int r = 0; r < size; ++r) send_counts[r] = static_cast<int>(outgoing[r].size()), sending += outgoing[r].size();
  MPI_Alltoall(send_counts.data(), 1, MPI_INT, receive_counts.data(), 1, MPI_INT, comm);
  std::vector<T> flat;
  flat.reserve(sending);
  for (int r = 0; r < size; ++r) {
    send_at[r] = static_cast<int>(flat.size());
    flat.insert(flat.end(), outgoing[r].begin(), outgoing[r].end());
    std::vector<T>().swap(outgoing[r]);
  }
  std::size_t total = 0;
  for (int r = 0; r < size; ++r) receive_at[r] = static_cast<int>(total), total += receive_counts[r];
  std::vector<T> incoming(total);
  MPI_Alltoallv(flat.data(), send_counts.data(), send_at.data(), record_type<T>(), incoming.data(),
                receive_counts.data(), receive_at.data(), record_type<T>(), comm);
  if (from_counts) *from_counts = receive_counts;
  return incoming;
}

std::uint64_t mix(std::uint64_t x) {  // splitmix64's finalizer
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

template <std::size_t N>
int rank_of_key(const std::array<std::uint64_t, N>& key, int size) {
  std::uint64_t h = 0;
  for (std::uint64_t k : key) h = mix(h ^ k);
  return static_cast<int>(h % static_cast<std::uint64_t>(size));
}

// ---------------------------------------------------------------------------------------------
// The part of the mesh this rank holds

// The rank whose run (run_of) of [0, total) holds id.
int run_owner(std::int64_t id, std::uint64_t total, int size) {
  int r = static_cast<int>((static_cast<unsigned __int128>(id) * size) / std::max<std::uint64_t>(total, 1));
  while (r + 1 < size && run_of(total, r + 1, size).first <= static_cast<std::uint64_t>(id)) ++r;
  while (r > 0 && run_of(total, r, size).first > static_cast<std::uint64_t>(id)) --r;
  return r;
}

struct Part {
  MPI_Comm comm;
  int rank = 0, size = 1;
  MeshTotals totals;
  MeshBlock block;
  // This rank's points are [first_point, first_point + block.points.size()).
  std::uint64_t run_start(std::uint64_t total, int r) const { return run_of(total, r, size).first; }
  int point_owner(Id id) const { return run_owner(id, totals.points, size); }
  bool valid(Id id) const { return id >= 0 && static_cast<std::uint64_t>(id) < totals.points; }
};

// What every rank counts; summed over the ranks at the end.
enum Count : int {
  bad_ids, inverted, flat, overfull, same_side, free_face_not_boundary, boundary_not_free_face, boundary_flipped,
  split_markers, unused, duplicate_points, input_not_boundary, boundary_not_input, input_flipped, faces, edges,
  used, free_faces, kCounts
};
using Counts = std::array<std::int64_t, kCounts>;

// The coordinates of the points `ids` (sorted, unique, valid) from their owners, in the same
// order; with `marked`, the owners record those points there (indexed by their own run).
std::vector<Point3> fetch_points(const Part& part, const std::vector<Id>& ids, std::vector<char>* marked) {
  std::vector<std::vector<Id>> requests(part.size);
  for (Id id : ids) requests[part.point_owner(id)].push_back(id);
  std::vector<int> from;
  const std::vector<Id> asked = all_to_all(part.comm, std::move(requests), &from);
  const std::uint64_t first = part.run_start(part.totals.points, part.rank);
  std::vector<std::vector<Point3>> replies(part.size);
  std::size_t at = 0;
  for (int r = 0; r < part.size; ++r)
    for (int i = 0; i < from[r]; ++i, ++at) {
      const std::uint64_t local = static_cast<std::uint64_t>(asked[at]) - first;
      replies[r].push_back(part.block.points[local]);
      if (marked) (*marked)[local] = 1;
    }
  // Owners' runs are in id order, so the replies in rank order follow `ids`.
  return all_to_all(part.comm, std::move(replies));
}

// Sorted unique valid ids of a set of rows; counts the invalid ones.
template <class Rows>
std::vector<Id> ids_of(const Part& part, const Rows& rows, std::int64_t* bad) {
  std::vector<Id> ids;
  for (const auto& row : rows)
    for (Id v : row) {
      if (part.valid(v)) ids.push_back(v);
      else if (bad) ++*bad;
    }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

const Point3& point_of(const std::vector<Id>& ids, const std::vector<Point3>& points, Id id) {
  return points[std::lower_bound(ids.begin(), ids.end(), id) - ids.begin()];
}

template <class Row>
bool all_valid(const Part& part, const Row& row) {
  return std::all_of(row.begin(), row.end(), [&](Id v) { return part.valid(v); });
}

// ---------------------------------------------------------------------------------------------
// The checks, one per step

// Tets: orientation and volume (6x, long double).
long double check_tets(const Part& part, Counts& counts) {
  std::vector<char> marked(part.block.points.size(), 0);  // this rank's points used by a tet
  const std::vector<Id> ids = ids_of(part, part.block.tets, &counts[bad_ids]);
  const std::vector<Point3> points = fetch_points(part, ids, &marked);
  long double volume6 = 0;
  for (const auto& tet : part.block.tets) {
    if (!all_valid(part, tet)) continue;
    const Point3 &a = point_of(ids, points, tet[0]), &b = point_of(ids, points, tet[1]),
                 &c = point_of(ids, points, tet[2]), &d = point_of(ids, points, tet[3]);
    const int orientation = tet_orientation(a, b, c, d);
    if (orientation < 0) ++counts[inverted];
    if (orientation == 0) ++counts[flat];
    volume6 += tet_volume6(a, b, c, d);
  }
  counts[used] = std::count(marked.begin(), marked.end(), 1);
  counts[unused] = static_cast<std::int64_t>(marked.size()) - counts[used];
  return volume6;
}

// A triangle as sorted ids and whether its given order is an even permutation of them.
struct FaceRecord {
  std::array<std::uint64_t, 3> key;
  std::int8_t even;
  std::int8_t boundary;  // 0: a tet's face (outward), 1: a row of the boundary file
};

FaceRecord face_record(Id a, Id b, Id c, bool boundary) {
  FaceRecord f{{std::uint64_t(a), std::uint64_t(b), std::uint64_t(c)}, 1, std::int8_t(boundary)};
  for (int i = 0; i < 2; ++i)  // bubble sort of three, each swap flips the parity
    for (int j = 0; j < 2 - i; ++j)
      if (f.key[j] > f.key[j + 1]) std::swap(f.key[j], f.key[j + 1]), f.even ^= 1;
  return f;
}

bool by_key(const FaceRecord& x, const FaceRecord& y) {
  return std::tie(x.key, x.boundary, x.even) < std::tie(y.key, y.boundary, y.even);
}

// The faces of this rank's tets that no other of its tets shares, to the ranks their keys hash
// to; the shared ones are settled here (two tets on opposite sides, or a violation). A third tet
// on another rank would leave its copy of a face paired here unpaired there, which then fails
// the boundary checks.
std::vector<std::vector<FaceRecord>> unpaired_tet_faces(const Part& part, Counts& counts) {
  static constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};  // outward_face
  std::vector<FaceRecord> local;
  local.reserve(4 * part.block.tets.size());
  for (const auto& tet : part.block.tets)
    if (all_valid(part, tet))
      for (const auto& f : kFace) local.push_back(face_record(tet[f[0]], tet[f[1]], tet[f[2]], false));
  std::sort(local.begin(), local.end(), by_key);
  std::vector<std::vector<FaceRecord>> outgoing(part.size);
  for (std::size_t i = 0; i < local.size();) {
    std::size_t j = i + 1;
    while (j < local.size() && local[j].key == local[i].key) ++j;
    if (j - i == 1) {
      outgoing[rank_of_key(local[i].key, part.size)].push_back(local[i]);
    } else {
      ++counts[faces];
      if (j - i > 2) ++counts[overfull];
      if (j - i == 2 && local[i].even == local[i + 1].even) ++counts[same_side];
    }
    i = j;
  }
  return outgoing;
}

// Faces: at most two tets on opposite sides; the free faces (one tet) are exactly the boundary
// file's triangles, facing out.
void check_faces(const Part& part, Counts& counts) {
  std::vector<std::vector<FaceRecord>> outgoing = unpaired_tet_faces(part, counts);
  for (std::size_t i = 0; i < part.block.faces.size(); ++i) {
    const auto& face = part.block.faces[i];
    if (part.block.face_marker[i] != 1) ++counts[split_markers];
    if (!all_valid(part, face)) continue;
    const FaceRecord r = face_record(face[0], face[1], face[2], true);
    outgoing[rank_of_key(r.key, part.size)].push_back(r);
  }
  std::vector<FaceRecord> here = all_to_all(part.comm, std::move(outgoing));
  std::sort(here.begin(), here.end(), by_key);
  for (std::size_t i = 0; i < here.size();) {
    std::size_t j = i;
    int tets = 0, listed = 0, tet_even = 0, listed_even = 0;
    for (; j < here.size() && here[j].key == here[i].key; ++j)
      here[j].boundary ? (++listed, listed_even += here[j].even) : (++tets, tet_even += here[j].even);
    if (tets > 0) ++counts[faces];
    if (tets > 2) ++counts[overfull];
    if (tets == 2 && tet_even != 1) ++counts[same_side];
    if (tets == 1) ++counts[free_faces];
    if (tets == 1 && listed == 0) ++counts[free_face_not_boundary];
    if (listed > 0 && (tets != 1 || listed > 1)) counts[boundary_not_free_face] += listed;
    if (tets == 1 && listed == 1 && tet_even != listed_even) ++counts[boundary_flipped];
    i = j;
  }
}

// Edges: how many distinct ones (for V-E+F-T); each rank's own distinct first, then across ranks.
void count_edges(const Part& part, Counts& counts) {
  using Edge = std::array<std::uint64_t, 2>;
  std::vector<Edge> local;
  local.reserve(6 * part.block.tets.size());
  for (const auto& tet : part.block.tets)
    if (all_valid(part, tet))
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
          local.push_back({std::uint64_t(std::min(tet[i], tet[j])), std::uint64_t(std::max(tet[i], tet[j]))});
  std::sort(local.begin(), local.end());
  local.erase(std::unique(local.begin(), local.end()), local.end());
  std::vector<std::vector<Edge>> outgoing(part.size);
  for (const Edge& e : local) outgoing[rank_of_key(e, part.size)].push_back(e);
  std::vector<Edge>().swap(local);
  std::vector<Edge> here = all_to_all(part.comm, std::move(outgoing));
  std::sort(here.begin(), here.end());
  counts[edges] = std::unique(here.begin(), here.end()) - here.begin();
}

using CoordinateBits = std::array<std::uint64_t, 3>;
CoordinateBits bits_of(const Point3& p) {
  CoordinateBits bits;
  for (int k = 0; k < 3; ++k) {
    const double x = p[k] + 0.0;  // -0.0 and 0.0 are the same coordinate
    std::memcpy(&bits[k], &x, sizeof x);
  }
  return bits;
}

// Points with identical coordinates.
void check_duplicate_points(const Part& part, Counts& counts) {
  std::vector<std::vector<CoordinateBits>> outgoing(part.size);
  for (const Point3& p : part.block.points) {
    const CoordinateBits bits = bits_of(p);
    outgoing[rank_of_key(bits, part.size)].push_back(bits);
  }
  std::vector<CoordinateBits> here = all_to_all(part.comm, std::move(outgoing));
  std::sort(here.begin(), here.end());
  counts[duplicate_points] = static_cast<std::int64_t>(here.size()) - (std::unique(here.begin(), here.end()) - here.begin());
}

// A triangle by the exact coordinates of its corners, sorted, with the parity of its order.
struct CornerRecord {
  std::array<std::uint64_t, 9> key;
  std::int8_t even;
  std::int8_t input;  // 1: an input triangle, 0: a boundary face of the mesh
};

CornerRecord corner_record(const Point3& a, const Point3& b, const Point3& c, bool input) {
  std::array<CoordinateBits, 3> corners{bits_of(a), bits_of(b), bits_of(c)};
  std::int8_t even = 1;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2 - i; ++j)
      if (corners[j + 1] < corners[j]) std::swap(corners[j], corners[j + 1]), even ^= 1;
  CornerRecord r{{}, even, std::int8_t(input)};
  for (int k = 0; k < 3; ++k) std::copy(corners[k].begin(), corners[k].end(), r.key.begin() + 3 * k);
  return r;
}

// The boundary faces are the input triangles, facing the same way (matched by coordinates).
void check_boundary_is_input(const Part& part, const SurfaceMesh* input, Counts& counts) {
  std::vector<std::vector<CornerRecord>> outgoing(part.size);
  const std::vector<Id> ids = ids_of(part, part.block.faces, nullptr);
  const std::vector<Point3> points = fetch_points(part, ids, nullptr);
  for (const auto& face : part.block.faces)
    if (all_valid(part, face)) {
      const CornerRecord r = corner_record(point_of(ids, points, face[0]), point_of(ids, points, face[1]),
                                           point_of(ids, points, face[2]), false);
      outgoing[rank_of_key(r.key, part.size)].push_back(r);
    }
  if (input)
    for (const Triangle& t : input->triangles) {
      const CornerRecord r = corner_record(input->points[t[0]], input->points[t[1]], input->points[t[2]], true);
      outgoing[rank_of_key(r.key, part.size)].push_back(r);
    }
  std::vector<CornerRecord> here = all_to_all(part.comm, std::move(outgoing));
  std::sort(here.begin(), here.end(), [](const CornerRecord& x, const CornerRecord& y) {
    return std::tie(x.key, x.input, x.even) < std::tie(y.key, y.input, y.even);
  });
  for (std::size_t i = 0; i < here.size();) {
    std::size_t j = i;
    int inputs = 0, faces_here = 0, input_even = 0, face_even = 0;
    for (; j < here.size() && here[j].key == here[i].key; ++j)
      here[j].input ? (++inputs, input_even += here[j].even) : (++faces_here, face_even += here[j].even);
    if (inputs > faces_here) counts[input_not_boundary] += inputs - faces_here;
    if (faces_here > inputs) counts[boundary_not_input] += faces_here - inputs;
    if (inputs == 1 && faces_here == 1 && input_even != face_even) ++counts[input_flipped];
    i = j;
  }
}

// ---------------------------------------------------------------------------------------------

std::string count_text(std::int64_t n, const std::string& what) { return std::to_string(n) + " " + what; }

// `boundary` names where the boundary triangles come from ("the boundary file").
std::vector<std::string> violations_of(const Counts& c, const std::string& boundary) {
  std::vector<std::string> v;
  const auto say = [&](Count k, const std::string& what) {
    if (c[k] > 0) v.push_back(count_text(c[k], what));
  };
  say(bad_ids, "vertex ids out of range in tets");
  say(inverted, "tets are inverted (negative orientation)");
  say(flat, "tets are flat");
  say(overfull, "triangles are in more than two tets");
  say(same_side, "triangles have both their tets on the same side (overlap)");
  say(free_face_not_boundary, "faces in one tet are missing from " + boundary);
  say(boundary_not_free_face, "triangles of " + boundary + " are not faces in exactly one tet");
  say(boundary_flipped, "triangles of " + boundary + " face into their tet");
  say(split_markers, "boundary triangles are parts of split input triangles (marker 2): check the TetGen files with "
                     "--allow-split-faces instead");
  say(unused, "vertices are in no tet");
  say(duplicate_points, "duplicate vertices (identical coordinates)");
  say(input_not_boundary, "input triangles are not boundary faces of the mesh (coordinates changed?)");
  say(boundary_not_input, "boundary faces of the mesh are not input triangles");
  say(input_flipped, "boundary faces face the other way than their input triangle");
  return v;
}

// ---------------------------------------------------------------------------------------------
// Reading the parts

// The lowest rank's non-empty text, on every rank ("" when every rank's is empty).
std::string first_nonempty(MPI_Comm comm, const std::string& text) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  int mine = text.empty() ? INT_MAX : rank, first = INT_MAX;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == INT_MAX) return "";
  int length = rank == first ? static_cast<int>(text.size()) : 0;
  MPI_Bcast(&length, 1, MPI_INT, first, comm);
  std::string out = rank == first ? text : std::string(static_cast<std::size_t>(length), ' ');
  MPI_Bcast(out.data(), length, MPI_CHAR, first, comm);
  return out;
}

// When any rank has an error, every rank throws InputError with the lowest such rank's message.
void throw_if_any(MPI_Comm comm, const std::string& error) {
  if (std::string first = first_nonempty(comm, error); !first.empty()) throw InputError(first);
}

// Runs read, turning what it throws into this rank's error (an allocation failure too: the
// other ranks must not wait for a rank that has given up).
template <class Read>
std::string error_of(const std::string& path, const Read& read) {
  try {
    read();
  } catch (const std::bad_alloc&) {
    return "out of memory reading '" + path + "': run the check on more ranks";
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

// What the check needs of the input, on every rank; the surface itself stays on rank 0.
struct InputFigures {
  SurfaceMesh surface;  // rank 0's only
  long double volume = 0, euler = 0;
};

InputFigures read_input(MPI_Comm comm, int rank, const std::string& path) {
  InputFigures input;
  throw_if_any(comm, rank == 0 ? error_of(path, [&] { input.surface = read_surface(path); }) : "");
  long double figures[2] = {0, 0};  // enclosed volume, Euler characteristic
  if (rank == 0) figures[0] = enclosed_volume_precise(input.surface), figures[1] = surface_euler_characteristic(input.surface);
  MPI_Bcast(figures, 2, MPI_LONG_DOUBLE, 0, comm);
  input.volume = figures[0], input.euler = figures[1];
  return input;
}

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

// This rank's files of an MSH set: rank 0 reads the named one, which lists the set; file i of
// the set is rank (i mod size)'s.
MshPart read_msh_share(const Part& part, const std::string& path) {
  MshPart mine;
  std::vector<std::string> files;
  throw_if_any(part.comm, part.rank == 0 ? error_of(path, [&] { files = read_msh_named(path, mine); }) : "");
  files = broadcast_lines(part.comm, files);
  std::string error;
  for (std::size_t i = 1; i < files.size() && error.empty(); ++i)
    if (static_cast<int>(i % static_cast<std::size_t>(part.size)) == part.rank)
      error = error_of(files[i], [&] { read_msh_file(files[i], mine); });
  throw_if_any(part.comm, error);
  return mine;
}

// A row of a file with its id: a point, or a tet's vertices or neighbours.
template <class Values>
struct Row {
  Id id;
  Values values;
};

// How a row given twice is taken: the same point in several MSH partition files, or a TetGen
// file's index, which must be unique.
enum class Repeats { same_values, refused };

// Rows to the owners of their ids (each rank the run of [0, total) the XDMF check's ranks read)
// and returned in id order: every id in [0, total) given, once or (same_values) with the same
// values each time; otherwise every rank throws InputError naming `file` (the lowest rank's find).
template <class Values>
std::vector<Values> place_rows(const Part& part, std::vector<Id>&& ids, std::vector<Values>&& values,
                               std::uint64_t total, Repeats repeats, const std::string& file) {
  // `file` names a TetGen file, or an MSH set ("the set of 'PATH'"), whose rows are nodes by tag.
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
                                              " (the tags must run from 1 to the highest)";
  throw_if_any(part.comm, error);
  return placed;
}

// The MSH set's points: node tags from 1 to the highest, a node in several files the same in each.
void place_msh_points(Part& part, MshPart& mine, const std::string& path) {
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
std::vector<std::array<Id, N>> rows_of_ids(const std::vector<std::int64_t>& values, std::int64_t base, bool keep_minus_one) {
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
      throw InputError(file + " has no '# partet mesh ID' line: only sets partet wrote are checked on several ranks; "
                       "check this one in one process");
  for (const auto& [file, id] : ids)
    if (id != ids.front().second)
      return "the files come from different runs: " + ids.front().first + " has mesh ID '" + ids.front().second +
             "', " + file + " has '" + id + "'";
  return "";
}

// What only a TetGen set has besides the mesh: its .neigh rows (tet id order, this rank's run).
struct TetgenExtras {
  std::vector<std::array<Id, 4>> neighbours;
  std::string set_violation;
};

TetgenExtras read_tetgen_parts(Part& part, const std::string& prefix) {
  TetgenExtras extras;
  std::vector<std::pair<std::string, std::string>> ids;
  const auto read = [&](TetgenFile file, TetgenFileLayout& layout, std::int64_t& base) {
    const std::string path = prefix + extension(file);
    TetgenRowsRead rows = read_tetgen_part(part, path, file, layout);
    base = numbering_base(part, rows, path);
    ids.push_back({path, first_nonempty(part.comm, rows.id)});
    return rows;
  };
  TetgenFileLayout node, ele, face, neigh;
  std::int64_t vertex_base = 0, tet_base = 0, unused_base = 0;
  {
    TetgenRowsRead rows = read(TetgenFile::node, node, vertex_base);
    part.totals.points = static_cast<std::uint64_t>(node.count);
    part.block.points = place_rows(part, row_ids(rows.index, vertex_base), std::move(rows.points), part.totals.points,
                                   Repeats::refused, prefix + ".node");
  }
  {
    TetgenRowsRead rows = read(TetgenFile::ele, ele, tet_base);
    part.totals.tets = static_cast<std::uint64_t>(ele.count);
    part.block.tets = place_rows(part, row_ids(rows.index, tet_base), rows_of_ids<4>(rows.values, vertex_base, false),
                                 part.totals.tets, Repeats::refused, prefix + ".ele");
  }
  {
    TetgenRowsRead rows = read(TetgenFile::face, face, unused_base);
    part.block.faces = rows_of_ids<3>(rows.values, vertex_base, false);
    part.block.face_marker = std::move(rows.markers);
    std::uint64_t faces = part.block.faces.size();
    MPI_Allreduce(MPI_IN_PLACE, &faces, 1, MPI_UINT64_T, MPI_SUM, part.comm);
    if (faces != static_cast<std::uint64_t>(face.count))
      throw InputError(prefix + ".face declares " + std::to_string(face.count) + " faces but has " +
                       std::to_string(faces) + " rows");  // on every rank
    part.totals.faces = faces;
  }
  {
    TetgenRowsRead rows = read(TetgenFile::neigh, neigh, unused_base);
    if (neigh.count != ele.count)
      throw InputError(prefix + ".neigh: " + std::to_string(neigh.count) + " neighbour rows for " +
                       std::to_string(ele.count) + " tetrahedra");
    extras.neighbours = place_rows(part, row_ids(rows.index, tet_base), rows_of_ids<4>(rows.values, tet_base, true),
                                   part.totals.tets, Repeats::refused, prefix + ".neigh");
  }
  extras.set_violation = check_set_id(ids);
  return extras;
}

// A tet's face (opposite one corner) with the tet and the neighbour its .neigh row names there.
struct NeighbourRecord {
  std::array<std::uint64_t, 3> key;
  Id tet, named;
};

// .neigh names, across each face, the tet on its other side (-1 on the boundary): the faces go to
// the ranks their keys hash to, which compare the two sides. Returns how many tet faces name
// another neighbour than the tets imply (faces in three or more tets are counted elsewhere).
std::int64_t check_neighbours(const Part& part, const std::vector<std::array<Id, 4>>& neighbours) {
  std::vector<std::vector<NeighbourRecord>> outgoing(part.size);
  const Id first = static_cast<Id>(run_of(part.totals.tets, part.rank, part.size).first);
  for (std::size_t t = 0; t < part.block.tets.size(); ++t) {
    const auto& tet = part.block.tets[t];
    for (int k = 0; k < 4; ++k) {
      std::array<std::uint64_t, 3> key;
      for (int j = 0, at = 0; j < 4; ++j)
        if (j != k) key[at++] = static_cast<std::uint64_t>(tet[j]);
      std::sort(key.begin(), key.end());
      outgoing[rank_of_key(key, part.size)].push_back({key, first + static_cast<Id>(t), neighbours[t][k]});
    }
  }
  std::vector<NeighbourRecord> here = all_to_all(part.comm, std::move(outgoing));
  std::sort(here.begin(), here.end(), [](const NeighbourRecord& a, const NeighbourRecord& b) { return a.key < b.key; });
  std::int64_t wrong = 0;
  for (std::size_t i = 0; i < here.size();) {
    std::size_t j = i;
    while (j < here.size() && here[j].key == here[i].key) ++j;
    if (j - i == 1) wrong += here[i].named != -1;
    if (j - i == 2) wrong += (here[i].named != here[i + 1].tet) + (here[i + 1].named != here[i].tet);
    i = j;
  }
  MPI_Allreduce(MPI_IN_PLACE, &wrong, 1, MPI_INT64_T, MPI_SUM, part.comm);
  return wrong;
}

// ---------------------------------------------------------------------------------------------

// The checks on the part every rank holds, their counts summed over the ranks, and the report.
DistributedCheckReport check_part(const Part& part, const InputFigures& input, const std::string& boundary) {
  Counts counts{};
  long double volume6 = check_tets(part, counts);
  check_faces(part, counts);
  count_edges(part, counts);
  check_duplicate_points(part, counts);
  check_boundary_is_input(part, part.rank == 0 ? &input.surface : nullptr, counts);
  MPI_Allreduce(MPI_IN_PLACE, counts.data(), kCounts, MPI_INT64_T, MPI_SUM, part.comm);
  MPI_Allreduce(MPI_IN_PLACE, &volume6, 1, MPI_LONG_DOUBLE, MPI_SUM, part.comm);

  DistributedCheckReport report;
  report.violations = violations_of(counts, boundary);
  report.vertices = static_cast<std::int64_t>(part.totals.points);
  report.tets = static_cast<std::int64_t>(part.totals.tets);
  report.boundary_faces = counts[free_faces];
  const long double tet_volume = volume6 / 6, surface_volume = input.volume;
  report.tet_volume = static_cast<double>(tet_volume);
  report.surface_volume = static_cast<double>(surface_volume);
  if (std::abs(tet_volume - surface_volume) >
      kCheckVolumeTolerance * std::max(std::abs(tet_volume), std::abs(surface_volume)))
    report.violations.push_back("tet volume " + std::to_string(report.tet_volume) +
                                " differs from the volume enclosed by the input, " +
                                std::to_string(report.surface_volume));
  report.euler_mesh = static_cast<long>(counts[used] - counts[edges] + counts[faces] - report.tets);
  const long input_chi = static_cast<long>(input.euler);
  report.euler_expected = input_chi / 2;
  if (2 * report.euler_mesh != input_chi)
    report.violations.push_back("V-E+F-T of the mesh is " + std::to_string(report.euler_mesh) +
                                ", expected half the Euler characteristic of the input, " + std::to_string(input_chi) +
                                "/2");
  return report;
}

Part part_of(MPI_Comm comm) {
  Part part;
  part.comm = comm;
  MPI_Comm_rank(comm, &part.rank);
  MPI_Comm_size(comm, &part.size);
  return part;
}

}  // namespace

DistributedCheckReport check_xdmf_set(MPI_Comm comm, const std::string& input_path, const std::string& prefix) {
  Part part = part_of(comm);
  // 1. The input, on rank 0 (its volume and Euler characteristic go to every rank).
  const InputFigures input = read_input(comm, part.rank, input_path);
  // 2. Every rank its rows of the HDF5 files.
  part.block = read_mesh_hdf5(comm, prefix + ".h5", prefix + "_boundary.h5", part.totals);
  // 3. The checks, their counts summed over the ranks.
  return check_part(part, input, "the boundary file");
}

DistributedCheckReport check_tetgen_set(MPI_Comm comm, const std::string& input_path, const std::string& prefix) {
  Part part = part_of(comm);
  // 1. The input, on rank 0.
  const InputFigures input = read_input(comm, part.rank, input_path);
  // 2. Every rank the same share of each file's bytes; points, tets and neighbour rows to their
  // owners (runs of ids), the faces kept where read.
  const TetgenExtras extras = read_tetgen_parts(part, prefix);
  // 3. The checks, their counts summed over the ranks; the .neigh rows and the set's ID.
  DistributedCheckReport report = check_part(part, input, "the .face file");
  if (const std::int64_t wrong = check_neighbours(part, extras.neighbours); wrong > 0)
    report.violations.push_back(std::to_string(wrong) + " tet faces have another neighbour in the .neigh file than "
                                                        "the tets imply");
  if (!extras.set_violation.empty()) report.violations.push_back(extras.set_violation);
  return report;
}

DistributedCheckReport check_msh_set(MPI_Comm comm, const std::string& input_path, const std::string& path) {
  Part part = part_of(comm);
  // 1. The input, on rank 0.
  const InputFigures input = read_input(comm, part.rank, input_path);
  // 2. Every rank its files of the set; the points to their owners (runs of ids).
  MshPart mine = read_msh_share(part, path);
  place_msh_points(part, mine, path);
  part.block.tets = std::move(mine.tets);
  part.block.faces = std::move(mine.triangles);
  part.block.face_marker.assign(part.block.faces.size(), 1);  // MSH has no split triangles to mark
  std::uint64_t counts[2] = {part.block.tets.size(), part.block.faces.size()};
  MPI_Allreduce(MPI_IN_PLACE, counts, 2, MPI_UINT64_T, MPI_SUM, comm);
  part.totals.tets = counts[0], part.totals.faces = counts[1];
  // 3. The checks, their counts summed over the ranks.
  return check_part(part, input, "the MSH files");
}

}  // namespace partet
