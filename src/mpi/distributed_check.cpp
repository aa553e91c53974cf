#include "mpi/distributed_check.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <optional>
#include <tuple>

#include "common/test_hooks.hpp"
#include "io/mesh_read.hpp"
#include "io/parallel_hdf5.hpp"
#include "mpi/check_exchange.hpp"
#include "mpi/check_reading.hpp"
#include "partet/errors.hpp"
#include "stages/check.hpp"

namespace partet {
namespace {

using namespace distributed;

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

// Sorted unique valid ids of the rows [first, last); counts the invalid ones.
template <class It>
std::vector<Id> ids_of(const Part& part, It first, It last, std::int64_t* bad) {
  std::vector<Id> ids;
  for (It row = first; row != last; ++row)
    for (Id v : *row) {
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

// The quality of every tet, and when there are planes of the seam zone's and the rest's.
struct Tallies {
  const std::vector<CutPlane>* planes = nullptr;
  QualityTally all, seam, elsewhere;
  void add(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
    all.add(a, b, c, d);
    if (planes) (in_seam_zone(*planes, a, b, c, d) ? seam : elsewhere).add(a, b, c, d);
  }
};

// Tets: orientation and volume (6x, long double), and their quality tallied. In runs of tets, one
// per pass, so that the ids and points fetched for them stay within kPassBytes.
long double check_tets(const Part& part, Counts& counts, Tallies& quality) {
  std::vector<char> marked(part.block.points.size(), 0);  // this rank's points used by a tet
  const std::size_t tets = part.block.tets.size();
  const std::uint64_t passes = passes_for(part.comm, 4 * tets, sizeof(Id) + sizeof(Point3));
  long double volume6 = 0;
  for (std::uint64_t pass = 0; pass < passes; ++pass) {
    const auto [first, last] = run_of(tets, static_cast<int>(pass), static_cast<int>(passes));
    const auto begin = part.block.tets.begin() + first, end = part.block.tets.begin() + last;
    const std::vector<Id> ids = ids_of(part, begin, end, &counts[bad_ids]);
    const std::vector<Point3> points = fetch_points(part, ids, &marked);
    for (auto it = begin; it != end; ++it) {
      const auto& tet = *it;
      if (!all_valid(part, tet)) continue;
      const Point3 &a = point_of(ids, points, tet[0]), &b = point_of(ids, points, tet[1]),
                   &c = point_of(ids, points, tet[2]), &d = point_of(ids, points, tet[3]);
      const int orientation = tet_orientation(a, b, c, d);
      if (orientation < 0) ++counts[inverted];
      if (orientation == 0) ++counts[flat];
      volume6 += tet_volume6(a, b, c, d);
      quality.add(a, b, c, d);
    }
  }
  counts[used] = std::count(marked.begin(), marked.end(), 1);
  counts[unused] = static_cast<std::int64_t>(marked.size()) - counts[used];
  return volume6;
}

// A tet's faces, each opposite its corner and outward (topology's outward_face).
constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

// A triangle as sorted ids and whether its given order is an even permutation of them.
struct FaceRecord {
  std::array<std::uint64_t, 3> key;
  std::int32_t rank;  // where it meets the other records of its key
  std::int8_t even;
  std::int8_t boundary;  // 0: a tet's face (outward), 1: a row of the boundary file
};

FaceRecord face_record(Id a, Id b, Id c, bool boundary) {
  FaceRecord f{{std::uint64_t(a), std::uint64_t(b), std::uint64_t(c)}, 0, 1, std::int8_t(boundary)};
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
// the boundary checks. Only the faces whose key falls in this pass.
std::vector<std::vector<FaceRecord>> unpaired_tet_faces(const Part& part, std::uint64_t pass, std::uint64_t passes,
                                                        Counts& counts) {
  std::vector<FaceRecord> local;
  local.reserve(4 * part.block.tets.size() / passes + 1024);
  for (const auto& tet : part.block.tets)
    if (all_valid(part, tet))
      for (const auto& f : kFace) {
        FaceRecord r = face_record(tet[f[0]], tet[f[1]], tet[f[2]], false);
        const KeyPlace place = place_of_key(r.key, part.size, passes);
        if (place.pass == pass) r.rank = place.rank, local.push_back(r);
      }
  std::sort(local.begin(), local.end(), by_key);
  std::vector<std::vector<FaceRecord>> outgoing(part.size);
  for (std::size_t i = 0; i < local.size();) {
    std::size_t j = i + 1;
    while (j < local.size() && local[j].key == local[i].key) ++j;
    if (j - i == 1) {
      outgoing[local[i].rank].push_back(local[i]);
    } else {
      ++counts[faces];
      if (j - i > 2) ++counts[overfull];
      if (j - i == 2 && local[i].even == local[i + 1].even) ++counts[same_side];
    }
    i = j;
  }
  return outgoing;
}

// The boundary faces of a set whose files do not list them (VTK files): the faces in one tet,
// outward, each kept by the rank its key hashes to.
using FreeFaces = std::vector<std::array<Id, 3>>;

void settle_faces(std::vector<FaceRecord>&& here, Counts& counts, FreeFaces* unlisted);

// Faces: at most two tets on opposite sides; the free faces (one tet) are exactly the boundary
// file's triangles, facing out. Without a boundary file (unlisted not null), the free faces are
// gathered into unlisted instead.
void check_faces(const Part& part, Counts& counts, FreeFaces* unlisted) {
  counts[split_markers] = std::count_if(part.block.face_marker.begin(), part.block.face_marker.end(),
                                        [](std::int32_t marker) { return marker != 1; });
  const std::uint64_t passes =
      passes_for(part.comm, 4 * part.block.tets.size() + part.block.faces.size(), sizeof(FaceRecord));
  for (std::uint64_t pass = 0; pass < passes; ++pass) {
    std::vector<std::vector<FaceRecord>> outgoing = unpaired_tet_faces(part, pass, passes, counts);
    for (const auto& face : part.block.faces) {
      if (!all_valid(part, face)) continue;
      const FaceRecord r = face_record(face[0], face[1], face[2], true);
      const KeyPlace place = place_of_key(r.key, part.size, passes);
      if (place.pass == pass) outgoing[place.rank].push_back(r);
    }
    settle_faces(all_to_all(part.comm, std::move(outgoing)), counts, unlisted);
  }
}

// The records of some keys, from every rank: all of each key's.
void settle_faces(std::vector<FaceRecord>&& here, Counts& counts, FreeFaces* unlisted) {
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
    if (tets == 1 && listed == 0 && unlisted) {
      const auto& k = here[i].key;  // even: the tet's outward order is the sorted one
      unlisted->push_back(here[i].even ? std::array<Id, 3>{Id(k[0]), Id(k[1]), Id(k[2])}
                                   : std::array<Id, 3>{Id(k[0]), Id(k[2]), Id(k[1])});
    } else if (tets == 1 && listed == 0) {
      ++counts[free_face_not_boundary];
    }
    if (listed > 0 && (tets != 1 || listed > 1)) counts[boundary_not_free_face] += listed;
    if (tets == 1 && listed == 1 && tet_even != listed_even) ++counts[boundary_flipped];
    i = j;
  }
}

// Edges: how many distinct ones (for V-E+F-T); each rank's own distinct first, then across ranks,
// in passes.
void count_edges(const Part& part, Counts& counts) {
  using Edge = std::array<std::uint64_t, 2>;
  const std::uint64_t passes = passes_for(part.comm, 6 * part.block.tets.size(), sizeof(Edge));
  for (std::uint64_t pass = 0; pass < passes; ++pass) {
    std::vector<std::vector<Edge>> outgoing(part.size);
    {
      std::vector<std::pair<Edge, int>> local;  // with its rank
      local.reserve(6 * part.block.tets.size() / passes + 1024);
      for (const auto& tet : part.block.tets)
        if (all_valid(part, tet))
          for (int i = 0; i < 4; ++i)
            for (int j = i + 1; j < 4; ++j) {
              const Edge e{std::uint64_t(std::min(tet[i], tet[j])), std::uint64_t(std::max(tet[i], tet[j]))};
              const KeyPlace place = place_of_key(e, part.size, passes);
              if (place.pass == pass) local.push_back({e, place.rank});
            }
      std::sort(local.begin(), local.end());
      local.erase(std::unique(local.begin(), local.end()), local.end());
      for (const auto& [e, rank] : local) outgoing[rank].push_back(e);
    }
    std::vector<Edge> here = all_to_all(part.comm, std::move(outgoing));
    std::sort(here.begin(), here.end());
    counts[edges] += std::unique(here.begin(), here.end()) - here.begin();
  }
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
    outgoing[place_of_key(bits, part.size, 1).rank].push_back(bits);
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

void match_corners(std::vector<CornerRecord>&& here, Counts& counts);

// The boundary faces are the input triangles, facing the same way (matched by coordinates).
// In passes (rank 0's records of the whole input's triangles are the most); each record's pass is
// found once, and the record made again in its pass (sorting and hashing coordinates costs more
// than an id's key).
void check_boundary_is_input(const Part& part, const SurfaceMesh* input, Counts& counts) {
  const std::vector<Id> ids = ids_of(part, part.block.faces.begin(), part.block.faces.end(), nullptr);
  const std::vector<Point3> points = fetch_points(part, ids, nullptr);
  const std::size_t faces_here = part.block.faces.size(), inputs = input ? input->triangles.size() : 0;
  const auto record = [&](std::size_t i) {  // the boundary faces, then the input's triangles
    if (i >= faces_here) {
      const Triangle& t = input->triangles[i - faces_here];
      return corner_record(input->points[t[0]], input->points[t[1]], input->points[t[2]], true);
    }
    const auto& face = part.block.faces[i];
    return corner_record(point_of(ids, points, face[0]), point_of(ids, points, face[1]), point_of(ids, points, face[2]),
                         false);
  };
  const std::uint64_t passes = passes_for(part.comm, faces_here + inputs, sizeof(CornerRecord));
  constexpr std::uint16_t kNone = UINT16_MAX;  // a face with ids out of range
  std::vector<std::uint16_t> pass_of(faces_here + inputs, kNone);
  for (std::size_t i = 0; i < pass_of.size(); ++i)
    if (i >= faces_here || all_valid(part, part.block.faces[i]))
      pass_of[i] = static_cast<std::uint16_t>(place_of_key(record(i).key, part.size, passes).pass);
  for (std::uint64_t pass = 0; pass < passes; ++pass) {
    std::vector<std::vector<CornerRecord>> outgoing(part.size);
    for (std::size_t i = 0; i < pass_of.size(); ++i)
      if (pass_of[i] == pass) {
        const CornerRecord r = record(i);
        outgoing[place_of_key(r.key, part.size, passes).rank].push_back(r);
      }
    match_corners(all_to_all(part.comm, std::move(outgoing)), counts);
  }
}

// The records of some keys, from every rank: all of each key's.
void match_corners(std::vector<CornerRecord>&& here, Counts& counts) {
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
  say(split_markers, "boundary triangles are parts of split input triangles (marker 2): check the mesh in one process "
                     "with --allow-split-faces instead");
  say(unused, "vertices are in no tet");
  say(duplicate_points, "duplicate vertices (identical coordinates)");
  say(input_not_boundary, "input triangles are not boundary faces of the mesh (coordinates changed?)");
  say(boundary_not_input, "boundary faces of the mesh are not input triangles");
  say(input_flipped, "boundary faces face the other way than their input triangle");
  return v;
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
  const Id first = static_cast<Id>(run_of(part.totals.tets, part.rank, part.size).first);
  const std::uint64_t passes = passes_for(part.comm, 4 * part.block.tets.size(), sizeof(NeighbourRecord));
  std::int64_t wrong = 0;
  for (std::uint64_t pass = 0; pass < passes; ++pass) {
    std::vector<std::vector<NeighbourRecord>> outgoing(part.size);
    for (std::size_t t = 0; t < part.block.tets.size(); ++t) {
      const auto& tet = part.block.tets[t];
      for (int k = 0; k < 4; ++k) {
        const auto key = face_record(tet[kFace[k][0]], tet[kFace[k][1]], tet[kFace[k][2]], false).key;
        const KeyPlace place = place_of_key(key, part.size, passes);
        if (place.pass == pass) outgoing[place.rank].push_back({key, first + static_cast<Id>(t), neighbours[t][k]});
      }
    }
    std::vector<NeighbourRecord> here = all_to_all(part.comm, std::move(outgoing));
    std::sort(here.begin(), here.end(), [](const NeighbourRecord& a, const NeighbourRecord& b) { return a.key < b.key; });
    for (std::size_t i = 0; i < here.size();) {
      std::size_t j = i;
      while (j < here.size() && here[j].key == here[i].key) ++j;
      if (j - i == 1) wrong += here[i].named != -1;
      if (j - i == 2) wrong += (here[i].named != here[i + 1].tet) + (here[i + 1].named != here[i].tet);
      i = j;
    }
  }
  reduce_in_place(&wrong, 1, MPI_INT64_T, MPI_SUM, part.comm);
  return wrong;
}

// ---------------------------------------------------------------------------------------------
// Quality: every rank's tally combined

// The k-th smallest (from 0) of every rank's values, exactly as one process's nth_element finds
// it: non-negative floats sort as their bit patterns, which are chosen a byte at a time, the
// highest first, by the counts of every rank.
float kth_smallest(MPI_Comm comm, const std::vector<float>& values, std::uint64_t k) {
  std::uint32_t prefix = 0, mask = 0;
  for (int shift = 24; shift >= 0; shift -= 8) {
    std::array<std::uint64_t, 256> counts{};
    for (float v : values) {
      std::uint32_t bits;
      std::memcpy(&bits, &v, sizeof bits);
      if ((bits & mask) == prefix) ++counts[(bits >> shift) & 255];
    }
    reduce_in_place(counts.data(), 256, MPI_UINT64_T, MPI_SUM, comm);
    std::uint32_t byte = 0;
    while (byte < 255 && k >= counts[byte]) k -= counts[byte++];
    prefix |= byte << shift, mask |= 0xFFu << shift;
  }
  float value;
  std::memcpy(&value, &prefix, sizeof value);
  return value;
}

MeshQuality quality_on_ranks(MPI_Comm comm, const QualityTally& tally) {
  std::array<std::int64_t, 4 + kDihedralBins.size()> counts{tally.tets, tally.below_5deg, tally.above_175deg,
                                                              tally.radius_edge_above_2};
  std::copy(tally.dihedral_histogram.begin(), tally.dihedral_histogram.end(), counts.begin() + 4);
  reduce_in_place(counts.data(), static_cast<int>(counts.size()), MPI_INT64_T, MPI_SUM, comm);
  long double sums[2] = {tally.amips_sum, tally.radius_edge_sum};
  reduce_in_place(sums, 2, MPI_LONG_DOUBLE, MPI_SUM, comm);
  double highest[4] = {tally.amips_max, tally.radius_edge_max, tally.largest_cos, -tally.smallest_cos};
  reduce_in_place(highest, 4, MPI_DOUBLE, MPI_MAX, comm);
  QualityTally all;
  all.tets = counts[0], all.below_5deg = counts[1], all.above_175deg = counts[2], all.radius_edge_above_2 = counts[3];
  std::copy(counts.begin() + 4, counts.end(), all.dihedral_histogram.begin());
  all.amips_sum = sums[0], all.radius_edge_sum = sums[1];
  all.amips_max = highest[0], all.radius_edge_max = highest[1];
  all.largest_cos = highest[2], all.smallest_cos = -highest[3];
  const double p99 =
      all.tets > 0 ? kth_smallest(comm, tally.amips, static_cast<std::uint64_t>(amips_p99_rank(all.tets))) : 0;
  return all.figures(p99);
}

// ---------------------------------------------------------------------------------------------

// The checks on the part every rank holds, their counts summed over the ranks, and the report.
// `boundary` names the files that list the boundary faces; "" when none does (VTK files): the
// faces in one tet are then taken for the boundary, and checked against the input.
DistributedCheckReport check_part(Part& part, const InputFigures& input, const std::string& boundary,
                                  const std::vector<CutPlane>* planes = nullptr) {
  test_hooks::check_failure(part.rank);
  test_hooks::check_stop(part.rank);
  Counts counts{};
  Tallies quality{planes, {}, {}, {}};
  long double volume6 = check_tets(part, counts, quality);
  if (test_hooks::check_finds_inverted_tet(part.rank)) ++counts[inverted];
  if (boundary.empty()) {
    FreeFaces unlisted;
    check_faces(part, counts, &unlisted);
    part.block.faces = std::move(unlisted);
    part.block.face_marker.assign(part.block.faces.size(), 1);
  } else {
    check_faces(part, counts, nullptr);
  }
  count_edges(part, counts);
  check_duplicate_points(part, counts);
  check_boundary_is_input(part, part.rank == 0 ? &input.surface() : nullptr, counts);
  reduce_in_place(counts.data(), kCounts, MPI_INT64_T, MPI_SUM, part.comm);
  reduce_in_place(&volume6, 1, MPI_LONG_DOUBLE, MPI_SUM, part.comm);

  DistributedCheckReport report;
  report.quality = quality_on_ranks(part.comm, quality.all);
  if (planes) report.zones = ZoneQuality{quality_on_ranks(part.comm, quality.seam),
                                         quality_on_ranks(part.comm, quality.elsewhere)};
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

// Every check on several ranks runs under a watch of its collective steps: a rank that stops,
// hangs or loses its node mid-check ends the job after the step limit, where it would hold the
// others in an exchange for ever (a batch job until its time limit).
class WatchedCheck {
 public:
  WatchedCheck(MPI_Comm comm, const std::string& path) {
    int size = 1;
    MPI_Comm_size(comm, &size);
    if (size > 1) watch_.emplace("checking '" + path + "'");
  }

 private:
  std::optional<mpi::CollectiveWatch> watch_;
};

Part part_of(MPI_Comm comm) {
  Part part;
  part.comm = comm;
  MPI_Comm_rank(comm, &part.rank);
  MPI_Comm_size(comm, &part.size);
  return part;
}

// An XDMF set's check once the input's figures are known: every rank its rows of the HDF5
// files, then the checks, their counts summed over the ranks.
DistributedCheckReport check_xdmf_files(Part& part, const InputFigures& input, const std::string& prefix,
                                        const std::string& suffix, const std::vector<CutPlane>* planes) {
  part.block = read_mesh_hdf5(part.comm, prefix + ".h5" + suffix, prefix + "_boundary.h5" + suffix, part.totals);
  mpi::collective_step_ended();
  return check_part(part, input, "the boundary file", planes);
}

// A TetGen set's check once the input's figures are known: every rank the same share of each
// file's bytes (points, tets and neighbour rows to their owners, the faces kept where read), then
// the checks, their counts summed over the ranks, the .neigh rows and the set's ID.
DistributedCheckReport check_tetgen_files(Part& part, const InputFigures& input, const std::string& prefix,
                                          const std::string& suffix, const std::vector<CutPlane>* planes) {
  const TetgenExtras extras = read_tetgen_parts(part, prefix, suffix);
  DistributedCheckReport report = check_part(part, input, "the .face file", planes);
  if (const std::int64_t wrong = check_neighbours(part, extras.neighbours); wrong > 0)
    report.violations.push_back(std::to_string(wrong) + " tet faces have another neighbour in the .neigh file than "
                                                        "the tets imply");
  if (!extras.set_violation.empty()) report.violations.push_back(extras.set_violation);
  return report;
}

}  // namespace

DistributedCheckReport check_xdmf_set(MPI_Comm comm, const std::string& input_path, const std::string& prefix) {
  const WatchedCheck watched(comm, prefix);
  Part part = part_of(comm);
  // The input, on rank 0 (its volume and Euler characteristic go to every rank).
  const InputFigures input = read_input(comm, part.rank, input_path);
  return check_xdmf_files(part, input, prefix, "", nullptr);
}

DistributedCheckReport check_tetgen_set(MPI_Comm comm, const std::string& input_path, const std::string& prefix) {
  const WatchedCheck watched(comm, prefix);
  Part part = part_of(comm);
  const InputFigures input = read_input(comm, part.rank, input_path);
  return check_tetgen_files(part, input, prefix, "", nullptr);
}

DistributedCheckReport check_unpublished_xdmf_set(MPI_Comm comm, const UnpublishedSet& set) {
  const WatchedCheck watched(comm, set.prefix);
  Part part = part_of(comm);
  const InputFigures input = held_input(comm, part.rank, set.input);
  return check_xdmf_files(part, input, set.prefix, set.suffix, &set.planes);
}

DistributedCheckReport check_unpublished_tetgen_set(MPI_Comm comm, const UnpublishedSet& set) {
  const WatchedCheck watched(comm, set.prefix);
  Part part = part_of(comm);
  const InputFigures input = held_input(comm, part.rank, set.input);
  return check_tetgen_files(part, input, set.prefix, set.suffix, &set.planes);
}

DistributedCheckReport check_mesh_file_set(MPI_Comm comm, const std::string& input_path, const std::string& path) {
  const WatchedCheck watched(comm, path);
  Part part = part_of(comm);
  // 1. The input, on rank 0.
  const InputFigures input = read_input(comm, part.rank, input_path);
  // 2. Every rank its files of the set; the points to their owners (runs of ids).
  read_mesh_part(part, path);
  // 3. The checks, their counts summed over the ranks.
  return check_part(part, input, boundary_list(path));
}

}  // namespace partet
