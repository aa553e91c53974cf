// The topology kernel: face keys, face grouping, neighbours, tet regions and local numbering,
// shared by every stage that works on tet meshes (internal header). Conventions for tets,
// faces and neighbours are those of mesh_types.hpp.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "partet/mesh_types.hpp"

namespace partet {

// A triangle's vertex set, independent of order and orientation: matches faces between tets,
// pieces and input surfaces.
struct FaceKey {
  std::int32_t v[3];
  explicit FaceKey(const Triangle& t) : v{t[0], t[1], t[2]} {
    if (v[0] > v[1]) std::swap(v[0], v[1]);
    if (v[1] > v[2]) std::swap(v[1], v[2]);
    if (v[0] > v[1]) std::swap(v[0], v[1]);
  }
  bool operator==(const FaceKey& o) const { return v[0] == o.v[0] && v[1] == o.v[1] && v[2] == o.v[2]; }
  bool operator<(const FaceKey& o) const { return std::lexicographical_compare(v, v + 3, o.v, o.v + 3); }
};

struct FaceKeyHash {
  std::size_t operator()(const FaceKey& k) const {
    std::uint64_t h = static_cast<std::uint32_t>(k.v[0]);
    h = h * 0x9E3779B97F4A7C15ull + static_cast<std::uint32_t>(k.v[1]);
    h = h * 0x9E3779B97F4A7C15ull + static_cast<std::uint32_t>(k.v[2]);
    h ^= h >> 31;
    h *= 0xBF58476D1CE4E5B9ull;
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};

// Each triangle rotated to start at its lowest vertex (orientation kept), then all ascending: an
// order that depends on the set of triangles alone, whatever order they were found in.
void sort_triangles(std::vector<Triangle>& triangles);

// True when a and b are the same triangle with the same orientation (up to rotation).
inline bool same_orientation(const Triangle& a, const Triangle& b) {
  for (int r = 0; r < 3; ++r)
    if (a[0] == b[r] && a[1] == b[(r + 1) % 3] && a[2] == b[(r + 2) % 3]) return true;
  return false;
}

// One face of one tet: slot = 4 * tet + j (the face opposite corner j).
struct FaceSlot {
  std::int32_t mid, high;  // the face's two larger vertex ids (the smallest is its bucket)
  std::uint32_t slot;
};

// Calls on_face(const FaceSlot* group, std::size_t count) once per distinct triangle of the
// tets, with the slots of the tets containing it. Faces are bucketed by their smallest vertex
// (a counting sort, linear) and matched within the small buckets: much faster than a hash map
// at millions of tets. Vertex ids must lie in [0, vertex_count).
template <class OnFace>
void for_each_face(const std::vector<Tet>& tets, std::size_t vertex_count, OnFace on_face);

// What compute_neighbours does with a triangle found in more than two tets.
enum class CrowdedFace { throw_error, leave_open };

// All neighbour relations, from the tets alone (faces matched by vertex ids). A face in more
// than two tets throws InternalError or stays -1 in all of them, as `crowded` says.
std::vector<Tet> compute_neighbours(const std::vector<Tet>& tets, std::size_t vertex_count,
                                    CrowdedFace crowded = CrowdedFace::throw_error);
// The same, with vertex_count taken from the largest id.
std::vector<Tet> compute_neighbours(const std::vector<Tet>& tets);

// Joins the open faces (neighbour -1) of tets that are the same triangle, as geogram's
// connect() does: used after tets were added or replaced piecewise. Faces left open are the
// boundary. `candidates` limits the search to those tets (all tets when null). Throws
// InternalError when more than two open faces are the same triangle.
void connect_open_faces(const std::vector<Tet>& tets, std::vector<Tet>& neighbours,
                        const std::vector<std::int32_t>* candidates = nullptr);
// The same for these open faces alone (4 * tet + j each).
void connect_faces(const std::vector<Tet>& tets, std::vector<Tet>& neighbours, const std::vector<std::uint64_t>& faces);

// Labels connected sets of tets: every tet with include(t) gets the label of its region; a
// region grows from tet t across face j when crosses(t, j) and the neighbour is included.
// Seeds are taken in tet order, so labels are numbered by each region's first tet. Tets not
// included get -1. Returns the number of regions.
template <class Include, class Crosses>
std::int32_t label_tet_regions(const std::vector<Tet>& neighbours, Include include, Crosses crosses,
                               std::vector<std::int32_t>& label);

// Renumbers the vertices a set of triangles uses to 0..n-1, keeping their order; the
// triangles are rewritten in place. Returns the original ids (local id -> original id).
// `scratch` must have one entry per original vertex, all -1; it is left that way.
std::vector<std::int32_t> renumber_locally(std::vector<Triangle>& triangles, std::vector<std::int32_t>& scratch);
// The same numbering without an array over every original vertex: for the small surfaces of
// re-meshed regions, where that array (4 bytes per mesh point) would cost more than the sort.
// The tets' (a seam chain's share, tens of thousands of tets) by one sort of their (id, corner)
// pairs, with no search per corner; the triangles' by a search per corner, as measured for the
// regions (the pairs' sort for them too gave the same files, but two runs could not rule out a
// slower seam healing).
std::vector<std::int32_t> renumber_locally(std::vector<Triangle>& triangles);
std::vector<std::int32_t> renumber_locally(std::vector<Tet>& tets);

// Disjoint sets of the ids [first, first + count) (union-find with path halving).
class DisjointSets {
 public:
  DisjointSets(std::int32_t first, std::size_t count) : first_(first), root_(count) {
    for (std::size_t i = 0; i < count; ++i) root_[i] = static_cast<std::int32_t>(i);
  }
  std::size_t size() const { return root_.size(); }
  // The set of id v, as an index below size().
  std::int32_t find(std::int32_t v) {
    std::int32_t x = v - first_;
    while (root_[x] != x) x = root_[x] = root_[root_[x]];
    return x;
  }
  void join(std::int32_t a, std::int32_t b) { root_[find(a)] = find(b); }

 private:
  std::int32_t first_;
  std::vector<std::int32_t> root_;
};

// Which of vertex_count vertices the cells (triangles or tets) use: as bytes, or as bits
// (used_vertices<bool>) for marks that live long.
template <class Flag = char, class Cell>
std::vector<Flag> used_vertices(std::size_t vertex_count, const std::vector<Cell>& cells) {
  std::vector<Flag> used(vertex_count, false);
  for (const auto& c : cells)
    for (auto v : c) used[v] = true;
  return used;
}

// Ids for the entries where used[i] is true, 0, 1, 2, ... in order; -1 elsewhere.
std::vector<std::int32_t> compact_ids(const std::vector<char>& used);

// Appends a locally numbered tet mesh: ids below global_ids.size() are surface points named by
// global_ids, later ones its Steiner points, appended to `points`. Neighbour ids are moved to
// the appended positions; open faces stay -1. Returns the index of the first appended tet.
std::int32_t append_local_mesh(const LocalTetMesh& local, const std::vector<std::int32_t>& global_ids,
                               std::vector<Point3>& points, std::vector<Tet>& tets, std::vector<Tet>& neighbours);

// ---------------------------------------------------------------------------------------------
// Template definitions.

namespace detail {
inline std::array<std::int32_t, 3> sorted_face(const Tet& t, int j) {
  std::int32_t a = t[(j + 1) & 3], b = t[(j + 2) & 3], c = t[(j + 3) & 3];
  if (a > b) std::swap(a, b);
  if (b > c) std::swap(b, c);
  if (a > b) std::swap(a, b);
  return {a, b, c};
}
}  // namespace detail

template <class OnFace>
void for_each_face(const std::vector<Tet>& tets, std::size_t vertex_count, OnFace on_face) {
  const std::size_t face_count = tets.size() * 4;
  std::vector<std::uint32_t> start(vertex_count + 1, 0);
  for (std::size_t i = 0; i < face_count; ++i) ++start[detail::sorted_face(tets[i / 4], int(i % 4))[0] + 1];
  for (std::size_t v = 0; v < vertex_count; ++v) start[v + 1] += start[v];
  std::vector<FaceSlot> entries(face_count);
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  for (std::size_t i = 0; i < face_count; ++i) {
    const auto f = detail::sorted_face(tets[i / 4], int(i % 4));
    entries[fill[f[0]]++] = {f[1], f[2], static_cast<std::uint32_t>(i)};
  }
  auto before = [](const FaceSlot& a, const FaceSlot& b) { return a.mid != b.mid ? a.mid < b.mid : a.high < b.high; };
  for (std::size_t v = 0; v < vertex_count; ++v) {
    FaceSlot* first = entries.data() + start[v];
    FaceSlot* last = entries.data() + start[v + 1];
    std::sort(first, last, before);
    for (FaceSlot* group = first; group != last;) {
      FaceSlot* group_end = group + 1;
      while (group_end != last && !before(*group, *group_end)) ++group_end;
      on_face(static_cast<const FaceSlot*>(group), static_cast<std::size_t>(group_end - group));
      group = group_end;
    }
  }
}

template <class Include, class Crosses>
std::int32_t label_tet_regions(const std::vector<Tet>& neighbours, Include include, Crosses crosses,
                               std::vector<std::int32_t>& label) {
  label.assign(neighbours.size(), -1);
  std::int32_t count = 0;
  std::vector<std::size_t> stack;
  for (std::size_t seed = 0; seed < neighbours.size(); ++seed) {
    if (label[seed] != -1 || !include(seed)) continue;
    label[seed] = count;
    stack.push_back(seed);
    while (!stack.empty()) {
      const std::size_t t = stack.back();
      stack.pop_back();
      for (int j = 0; j < 4; ++j) {
        const std::int32_t nb = neighbours[t][j];
        if (nb < 0 || label[nb] != -1 || !crosses(t, j) || !include(static_cast<std::size_t>(nb))) continue;
        label[nb] = count;
        stack.push_back(static_cast<std::size_t>(nb));
      }
    }
    ++count;
  }
  return count;
}

}  // namespace partet
