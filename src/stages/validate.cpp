// Surface checks run before meshing. TetGen either aborts or silently produces an empty mesh
// on surfaces that are open, non-manifold, inconsistently oriented or self-intersecting, so we
// name the first problem ourselves. The checks work on the triangle soup directly, which keeps
// them valid for inputs that a halfedge structure could not even represent.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/box_intersection_d.h>
#include <CGAL/intersections.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "common/parallel.hpp"
#include "partet/errors.hpp"
#include "stages/geometry.hpp"
#include "stages/validate.hpp"

namespace partet {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using KPoint = Kernel::Point_3;

std::string str(long long n) { return std::to_string(n); }

KPoint to_kernel(const Point3& p) { return {p[0], p[1], p[2]}; }

std::uint64_t mix(std::uint64_t x) {
  x ^= x >> 33;
  x *= 0xff51afd7ed558ccdULL;
  x ^= x >> 33;
  x *= 0xc4ceb9fe1a85ec53ULL;
  x ^= x >> 33;
  return x;
}

bool is_collinear(const Triangle& t, const std::vector<Point3>& points) {
  return CGAL::collinear(to_kernel(points[t[0]]), to_kernel(points[t[1]]), to_kernel(points[t[2]]));
}

void check_indices_and_coordinates(const SurfaceMesh& surface, const char* what) {
  const auto vertex_count = static_cast<std::int64_t>(surface.points.size());
  if (surface.triangles.empty()) throw InputError(std::string(what) + " is empty: it has no faces");
  for (std::size_t f = 0; f < surface.triangles.size(); ++f)
    for (std::int32_t v : surface.triangles[f])
      if (v < 0 || v >= vertex_count)
        throw InputError(std::string(what) + " has an invalid face: face " + str(f) + " refers to vertex " + str(v) +
                         ", but there are only " + str(vertex_count) + " vertices");
  for (const Triangle& t : surface.triangles)
    for (std::int32_t v : t) {
      const Point3& p = surface.points[v];
      if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
        throw InputError(std::string(what) + " has a non-finite coordinate at vertex " + str(v) + " " +
                         coordinates_text(p));
    }
}

// A share of the input as its checks see it: a problem is the share's when it owns the lowest
// vertex involved (of a face, of an edge) or the vertex itself.
struct Share {
  const std::vector<Point3>& points;
  const std::vector<Triangle>& faces;
  const ShareNumbering& ids;
  bool owns_face(std::size_t f) const {
    const Triangle& t = faces[f];
    return ids.owns(std::min({t[0], t[1], t[2]}));
  }
  std::int64_t vertex(std::int32_t v) const { return ids.vertex_id(v); }
};

bool repeats_a_vertex(const Triangle& t) { return t[0] == t[1] || t[0] == t[2] || t[1] == t[2]; }

void find_degenerate_faces(const Share& share, InputFindings& found) {
  for (std::size_t f = 0; f < share.faces.size(); ++f) {
    if (!share.owns_face(f)) continue;
    const Triangle& t = share.faces[f];
    if (t[0] == t[1] || t[0] == t[2])
      found.repeated.add(share.ids.face_id(f), share.vertex(t[0]));
    else if (t[1] == t[2])
      found.repeated.add(share.ids.face_id(f), share.vertex(t[1]));
    else if (is_collinear(t, share.points))
      found.collinear.add(share.ids.face_id(f));
  }
}

// Two used vertices at the same position make the surface touch itself there, which TetGen
// cannot mesh; an unmerged soup (e.g. from STL) also shows up here first. Vertices at one
// position are in one share (vertex_shares), and every face around an owned vertex is in it.
void find_duplicate_vertices(const Share& share, InputFindings& found) {
  const std::vector<Point3>& points = share.points;
  std::vector<char> candidate(points.size(), 0);  // used and owned
  std::size_t candidates = 0;
  for (const Triangle& t : share.faces)
    for (std::int32_t v : t)
      if (!candidate[v] && share.ids.owns(v)) candidate[v] = 1, ++candidates;

  auto hash_point = [](const Point3& p) {
    std::uint64_t h = 0;
    for (double c : p) {
      double normalized = c == 0 ? 0.0 : c;  // -0.0 and 0.0 are the same position
      std::uint64_t bits;
      std::memcpy(&bits, &normalized, sizeof bits);
      h = mix(h ^ bits);
    }
    return h;
  };
  std::size_t capacity = 16;
  while (capacity < 2 * candidates) capacity *= 2;
  const std::size_t mask = capacity - 1;
  constexpr std::uint32_t kEmpty = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> slots(capacity, kEmpty);
  // In ascending order, so the first duplicate is the lowest vertex at a position seen before.
  // The slots are read at random (memory latency): each vertex's is fetched a few vertices ahead.
  constexpr std::size_t kAhead = 8;
  for (std::size_t v = 0; v < points.size() && v < kAhead; ++v)
    __builtin_prefetch(&slots[hash_point(points[v]) & mask]);
  for (std::size_t v = 0; v < points.size(); ++v) {
    if (v + kAhead < points.size()) __builtin_prefetch(&slots[hash_point(points[v + kAhead]) & mask]);
    if (!candidate[v]) continue;
    for (std::size_t slot = hash_point(points[v]) & mask;; slot = (slot + 1) & mask) {
      if (slots[slot] == kEmpty) {
        slots[slot] = static_cast<std::uint32_t>(v);
        break;
      }
      if (points[slots[slot]] == points[v]) {
        const std::int64_t later = share.vertex(static_cast<std::int32_t>(v));
        if (later < found.duplicate.order) found.duplicate_at = points[slots[slot]];  // the earlier one
        found.duplicate.add(later, share.vertex(static_cast<std::int32_t>(slots[slot])));
        break;
      }
    }
  }
}

// The corners (3 f + c: the edge from corner c to c + 1 of face f) bucketed by their edge's lower
// vertex, a range of lower vertices at a time (a counting sort), so each edge's uses are found
// in a bucket of a few entries instead of a hash table of the whole surface. The ranges keep the
// buckets small: the check of a 10.9M-face input held 0.94 GB with all of them at once.
class EdgeBuckets {
 public:
  struct Use {
    std::int32_t higher;  // the edge's other vertex
    std::int32_t face;
    bool operator<(const Use& o) const { return higher < o.higher || (higher == o.higher && face < o.face); }
  };

  EdgeBuckets(const std::vector<Triangle>& triangles, std::size_t vertex_count, std::size_t corners_per_range)
      : triangles_(triangles), first_(vertex_count + 1, 0), corners_per_range_(corners_per_range) {
    for (std::size_t corner = 0; corner < 3 * triangles.size(); ++corner) ++first_[lower(corner) + 1];
    for (std::size_t v = 0; v < vertex_count; ++v) first_[v + 1] += first_[v];
  }

  // Calls edge(v, uses) for each edge (v, w > v) with its uses, in face order: by lower vertex v,
  // then higher vertex w.
  template <class Edge>
  void for_each_edge(const Edge& edge) {
    const std::size_t vertex_count = first_.size() - 1;
    std::vector<Use> uses;
    for (std::size_t begin = 0, end = 0; begin < vertex_count; begin = end) {
      end = begin + 1;
      while (end < vertex_count && first_[end + 1] - first_[begin] <= corners_per_range_) ++end;
      fill(begin, end, uses);
      for (std::size_t v = begin; v < end; ++v) {
        // The edges' faces are read at random (memory latency): fetch those a few vertices on.
        if (v + kAhead < end)
          for (std::size_t k = first_[v + kAhead]; k < first_[v + kAhead + 1]; ++k)
            __builtin_prefetch(&triangles_[static_cast<std::size_t>(uses[k - first_[begin]].face)]);
        const auto from = uses.begin() + static_cast<long>(first_[v] - first_[begin]);
        const auto to = uses.begin() + static_cast<long>(first_[v + 1] - first_[begin]);
        std::sort(from, to);  // each edge's uses together, in face order
        for (auto i = from; i != to;) {
          auto j = i;
          while (j != to && j->higher == i->higher) ++j;
          edge(static_cast<std::int32_t>(v), &*i, static_cast<std::size_t>(j - i));
          i = j;
        }
      }
    }
  }

 private:
  std::int32_t from(std::size_t corner) const { return triangles_[corner / 3][corner % 3]; }
  std::int32_t to(std::size_t corner) const { return triangles_[corner / 3][(corner % 3 + 1) % 3]; }
  std::int32_t lower(std::size_t corner) const { return std::min(from(corner), to(corner)); }

  // The uses of the edges whose lower vertex is in [begin, end), bucketed.
  void fill(std::size_t begin, std::size_t end, std::vector<Use>& uses) const {
    uses.resize(first_[end] - first_[begin]);
    std::vector<std::size_t> next(first_.begin() + static_cast<long>(begin), first_.begin() + static_cast<long>(end));
    for (std::size_t corner = 0; corner < 3 * triangles_.size(); ++corner) {
      const auto v = static_cast<std::size_t>(lower(corner));
      if (v < begin || v >= end) continue;
      uses[next[v - begin]++ - first_[begin]] = {std::max(from(corner), to(corner)),
                                                 static_cast<std::int32_t>(corner / 3)};
    }
  }

  static constexpr std::size_t kAhead = 4;
  const std::vector<Triangle>& triangles_;
  std::vector<std::size_t> first_;  // bucket of lower vertex v: [first_[v], first_[v + 1])
  std::size_t corners_per_range_;
};

// The corner of face f along the edge (v, w).
int corner_along(const Triangle& t, std::int32_t v, std::int32_t w) {
  int c = 0;
  while (std::minmax(t[c], t[(c + 1) % 3]) != std::minmax(v, w)) ++c;
  return c;
}
// Every edge at an owned vertex is used by exactly two faces traversing it in opposite directions;
// a problem is counted by the share owning the edge's lower vertex (which holds every face of
// the edge). Returns, per local corner 3 f + c, the local face across the edge from corner c to
// c + 1 of face f when that edge is at an owned vertex and shared properly, else -1.
std::vector<std::int32_t> find_edge_problems(const Share& share, InputFindings& found, std::size_t corners_per_range) {
  const std::vector<Triangle>& faces = share.faces;
  std::vector<std::int32_t> across(3 * faces.size(), -1);
  auto face_id = [&](std::int32_t f) { return share.ids.face_id(static_cast<std::size_t>(f)); };
  EdgeBuckets(faces, share.points.size(), corners_per_range)
      .for_each_edge([&](std::int32_t v, const EdgeBuckets::Use* uses, std::size_t count) {
        const std::int32_t w = uses[0].higher, f0 = uses[0].face;
        const bool counted = share.ids.owns(v);
        if (!counted && !share.ids.owns(w)) return;  // some of its faces may be in other shares only
        const int c0 = corner_along(faces[f0], v, w);
        // The corner that introduces the edge: its lowest face's corner along it.
        const std::int64_t introduced = 3 * face_id(f0) + c0;
        if (count == 1) {
          if (counted) found.border.add(introduced, share.vertex(faces[f0][c0]));
          return;
        }
        if (count > 2) {
          if (counted) found.crowded.add(introduced, share.vertex(v), share.vertex(w));
          return;
        }
        const std::int32_t f1 = uses[1].face;
        const int c1 = corner_along(faces[f1], v, w);
        if ((faces[f0][c0] < faces[f0][(c0 + 1) % 3]) == (faces[f1][c1] < faces[f1][(c1 + 1) % 3])) {
          if (counted) found.misoriented.add(introduced, face_id(f0), face_id(f1), share.vertex(v), share.vertex(w));
          return;
        }
        across[3 * static_cast<std::size_t>(f0) + static_cast<std::size_t>(c0)] = f1;
        across[3 * static_cast<std::size_t>(f1) + static_cast<std::size_t>(c1)] = f0;
      });
  return across;
}

// The faces around each owned vertex must form a single fan. Walk around each vertex: from corner
// (f, v), cross the edge leaving v to the other face of that edge. With every edge shared by
// exactly two opposite faces this is a permutation of the corners, and its cycles at v are the
// fans of faces around v. Skipped when an edge here is not shared properly: that problem is
// reported first (by the share owning the edge).
void find_split_fans(const Share& share, const std::vector<std::int32_t>& across, InputFindings& found) {
  const std::vector<Triangle>& faces = share.faces;
  for (std::size_t corner = 0; corner < across.size(); ++corner)
    if (across[corner] < 0 && share.ids.owns(faces[corner / 3][corner % 3])) return;
  std::vector<char> visited(across.size(), 0);
  std::vector<std::uint32_t> fans(share.points.size(), 0);
  for (std::size_t start = 0; start < across.size(); ++start) {
    const std::int32_t v = faces[start / 3][start % 3];
    if (visited[start] || !share.ids.owns(v)) continue;
    ++fans[v];
    std::size_t corner = start;
    while (!visited[corner]) {
      visited[corner] = 1;
      const std::int32_t g = across[corner];
      int c = 0;
      while (faces[g][c] != v) ++c;
      corner = 3 * static_cast<std::size_t>(g) + c;
    }
  }
  for (std::size_t v = 0; v < fans.size(); ++v)
    if (fans[v] > 1) found.split.add(share.vertex(static_cast<std::int32_t>(v)), fans[v]);
}

// Six times the signed volume of the tet from `origin` to face t.
long double six_volume_term(const std::vector<Point3>& points, const Triangle& t, const long double origin[3]) {
  long double a[3], b[3], c[3];
  for (int i = 0; i < 3; ++i) {
    a[i] = points[t[0]][i] - origin[i];
    b[i] = points[t[1]][i] - origin[i];
    c[i] = points[t[2]][i] - origin[i];
  }
  return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
}

// Volumes are measured from the centre of the used vertices' box: small terms, so far-from-origin
// inputs (or a far unused vertex) do not lose the volume to cancellation.
void box_centre(const Point3& low, const Point3& high, long double origin[3]) {
  for (int i = 0; i < 3; ++i) origin[i] = (static_cast<long double>(low[i]) + high[i]) / 2;
}

void used_box(const SurfaceMesh& surface, Point3& low, Point3& high) {
  if (surface.triangles.empty()) return;
  low = high = surface.points[surface.triangles[0][0]];
  for (const Triangle& t : surface.triangles)
    for (std::int32_t v : t)
      for (int i = 0; i < 3; ++i) {
        low[i] = std::min(low[i], surface.points[v][i]);
        high[i] = std::max(high[i], surface.points[v][i]);
      }
}

void add_volume(const Share& share, InputFindings& found) {
  long double origin[3];
  box_centre(share.ids.box_low, share.ids.box_high, origin);
  for (std::size_t f = 0; f < share.faces.size(); ++f)
    if (share.owns_face(f)) found.six_volume += six_volume_term(share.points, share.faces[f], origin);
}

}  // namespace

InputFindings check_share(const InputShare& share) { return check_share(share.points, share.faces, share.numbering); }

InputFindings check_share(const std::vector<Point3>& points, const std::vector<Triangle>& faces,
                          const ShareNumbering& numbering, std::size_t corners_per_range) {
  const Share share{points, faces, numbering};
  InputFindings found;
  find_degenerate_faces(share, found);
  find_duplicate_vertices(share, found);
  // The edges need proper triangles; a face repeating a vertex is reported first (by its share).
  if (std::none_of(faces.begin(), faces.end(), repeats_a_vertex))
    find_split_fans(share, find_edge_problems(share, found, corners_per_range), found);
  add_volume(share, found);
  return found;
}

InputFindings check_whole(const SurfaceMesh& surface) {
  ShareNumbering whole;
  used_box(surface, whole.box_low, whole.box_high);
  return check_share(surface.points, surface.triangles, whole);
}

InputFindings check_whole(const SurfaceMesh& surface, int shares) {
  if (shares <= 1) return check_whole(surface);
  const std::vector<std::uint16_t> owner = vertex_shares(surface.points, shares);
  std::vector<InputFindings> found(static_cast<std::size_t>(shares));
  parallel_for(found.size(), static_cast<unsigned>(shares), [&](std::size_t s) {
    InputShareBuilder builder(static_cast<int>(s), shares, surface.points.size(), surface.triangles.size());
    builder.add_vertex_shares(owner.data(), owner.size());
    builder.add_faces(surface.triangles.data(), surface.triangles.size());
    builder.add_points(surface.points.data(), surface.points.size());
    found[s] = check_share(builder.finish());
  });
  InputFindings merged;
  for (const InputFindings& share : found) merged.merge(share);
  return merged;
}

std::vector<std::int32_t> faces_across_edges(const SurfaceMesh& surface, const std::string& subject,
                                             std::size_t corners_per_range) {
  const ShareNumbering whole;
  InputFindings found;
  std::vector<std::int32_t> across =
      find_edge_problems({surface.points, surface.triangles, whole}, found, corners_per_range);
  throw_first_problem(found, subject);  // only the edges' problems were looked for
  return across;
}

namespace {

// True if faces a and b share more than a common edge or vertex (mirrors the rules of CGAL's
// Polygon_mesh_processing::does_self_intersect, but on indices so it works on any soup).
bool faces_intersect(const Triangle& a, const Triangle& b, const std::vector<Point3>& points) {
  int shared = 0, shared_a[3], shared_b[3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (a[i] == b[j]) {
        shared_a[shared] = i;
        shared_b[shared] = j;
        ++shared;
      }
  auto p = [&](std::int32_t v) { return to_kernel(points[v]); };
  if (shared == 3) return true;
  if (shared == 2) {
    // Sharing an edge, they overlap only if coplanar with both far corners on the same side.
    const int far_a = 3 - shared_a[0] - shared_a[1];
    const int far_b = 3 - shared_b[0] - shared_b[1];
    const KPoint s = p(a[shared_a[0]]), t = p(a[shared_a[1]]);
    const KPoint ra = p(a[far_a]), rb = p(b[far_b]);
    return CGAL::coplanar(s, t, ra, rb) && CGAL::coplanar_orientation(s, t, ra, rb) == CGAL::POSITIVE;
  }
  const Kernel::Triangle_3 ta(p(a[0]), p(a[1]), p(a[2]));
  const Kernel::Triangle_3 tb(p(b[0]), p(b[1]), p(b[2]));
  if (shared == 1) {
    // Sharing a vertex, they overlap elsewhere only if an opposite edge meets the other face.
    const int i = shared_a[0], j = shared_b[0];
    const Kernel::Segment_3 opposite_a(p(a[(i + 1) % 3]), p(a[(i + 2) % 3]));
    const Kernel::Segment_3 opposite_b(p(b[(j + 1) % 3]), p(b[(j + 2) % 3]));
    return CGAL::do_intersect(ta, opposite_b) || CGAL::do_intersect(tb, opposite_a);
  }
  return CGAL::do_intersect(ta, tb);
}

// The shells: triangles joined across shared edges; returns each triangle's shell.
std::vector<std::int32_t> shell_of_triangles(const SurfaceMesh& surface, std::int32_t& count) {
  // A closed manifold surface (validate_topology has passed): one face across each edge.
  const std::vector<std::int32_t> across = faces_across_edges(surface, "input");
  std::vector<std::int32_t> shell(surface.triangles.size(), -1);
  count = 0;
  std::vector<std::size_t> stack;
  for (std::size_t seed = 0; seed < shell.size(); ++seed) {
    if (shell[seed] >= 0) continue;
    shell[seed] = count;
    stack.push_back(seed);
    while (!stack.empty()) {
      const std::size_t f = stack.back();
      stack.pop_back();
      for (int c = 0; c < 3; ++c)
        if (const std::int32_t g = across[3 * f + c]; g >= 0 && shell[g] < 0) {
          shell[g] = count;
          stack.push_back(static_cast<std::size_t>(g));
        }
    }
    ++count;
  }
  return shell;
}

// How many times the triangles wind around p (a point on none of them): the sum of their signed
// solid angles over 4 pi, rounded (Van Oosterom and Strackee).
long winding_number(const SurfaceMesh& surface, const std::vector<std::size_t>& triangles, const Point3& p) {
  long double total = 0;
  for (std::size_t f : triangles) {
    const Triangle& t = surface.triangles[f];
    const Point3 a = sub(surface.points[t[0]], p), b = sub(surface.points[t[1]], p), c = sub(surface.points[t[2]], p);
    const double la = norm(a), lb = norm(b), lc = norm(c);
    const double numerator = dot(a, cross(b, c));
    const double denominator = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
    total += 2 * std::atan2(numerator, denominator);
  }
  return std::lround(static_cast<double>(total / (4 * kPi)));
}

}  // namespace

void check_shell_nesting(const SurfaceMesh& surface) {
  std::int32_t count = 0;
  const std::vector<std::int32_t> shell = shell_of_triangles(surface, count);
  if (count < 2) return;
  std::vector<std::vector<std::size_t>> faces(count);
  for (std::size_t f = 0; f < shell.size(); ++f) faces[shell[f]].push_back(f);
  for (std::int32_t s = 0; s < count; ++s) {
    const std::int32_t vertex = surface.triangles[faces[s].front()][0];
    long depth = 0;
    for (std::int32_t t = 0; t < count; ++t)
      if (t != s && winding_number(surface, faces[t], surface.points[vertex]) != 0) ++depth;
    SurfaceMesh one{surface.points, {}};
    for (std::size_t f : faces[s]) one.triangles.push_back(surface.triangles[f]);
    const bool outward = enclosed_volume_precise(one) > 0;
    if (outward != (depth % 2 == 0))
      throw InputError("input shells are nested inconsistently: the shell through vertex " + str(vertex) +
                       " lies inside " + str(depth) + " other shell" + (depth == 1 ? "" : "s") + " but faces " +
                       (outward ? "outwards" : "inwards") +
                       " (a cavity must face into the void, an island inside a cavity outwards)");
  }
}

void validate_indices(const SurfaceMesh& surface) { check_indices_and_coordinates(surface, "input"); }

void validate_topology(const SurfaceMesh& surface) {
  check_indices_and_coordinates(surface, "input");
  throw_first_problem(check_whole(surface), "input");
}

void check_no_self_intersections(const SurfaceMesh& surface, const char* what) {
  // The intersection predicates require proper triangles.
  check_indices_and_coordinates(surface, what);
  const ShareNumbering whole;
  InputFindings degenerate;
  find_degenerate_faces({surface.points, surface.triangles, whole}, degenerate);
  throw_first_problem(degenerate, what);

  using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, std::uint32_t>;
  const std::vector<Point3>& points = surface.points;
  const std::vector<Triangle>& triangles = surface.triangles;
  std::vector<Box> boxes;
  boxes.reserve(triangles.size());
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    const Triangle& t = triangles[f];
    CGAL::Bbox_3 box = to_kernel(points[t[0]]).bbox() + to_kernel(points[t[1]]).bbox() + to_kernel(points[t[2]]).bbox();
    boxes.emplace_back(box, static_cast<std::uint32_t>(f));
  }

  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  auto report = [&](const Box& a, const Box& b) {
    std::uint32_t f = a.info(), g = b.info();
    if (faces_intersect(triangles[f], triangles[g], points)) pairs.emplace_back(std::min(f, g), std::max(f, g));
  };
  CGAL::box_self_intersection_d(boxes.begin(), boxes.end(), report);
  if (pairs.empty()) return;

  // The box traversal order is an implementation detail; report the lowest pair.
  auto first = *std::min_element(pairs.begin(), pairs.end());
  throw InputError(std::string(what) + " self-intersects: faces " + str(first.first) + " and " + str(first.second) +
                   " intersect (" + str(static_cast<long long>(pairs.size())) + " intersecting pair" +
                   (pairs.size() > 1 ? "s" : "") + ")");
}

double enclosed_volume(const SurfaceMesh& surface) { return static_cast<double>(enclosed_volume_precise(surface)); }

long double enclosed_volume_precise(const SurfaceMesh& surface) {
  long double origin[3] = {0, 0, 0};
  Point3 low{}, high{};
  used_box(surface, low, high);
  box_centre(low, high, origin);
  long double six_volume = 0;
  for (const Triangle& t : surface.triangles) six_volume += six_volume_term(surface.points, t, origin);
  return six_volume / 6;
}

}  // namespace partet