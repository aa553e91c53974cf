// Small geometric and combinatorial helpers shared by the stage unit tests. Everything here is
// computed independently of the code under test (no use of partet internals).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "partet/mesh_types.hpp"

namespace partet::test {

inline Point3 sub(const Point3& a, const Point3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Point3 cross(const Point3& a, const Point3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double dot(const Point3& a, const Point3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline double norm(const Point3& a) { return std::sqrt(dot(a, a)); }

inline Point3 triangle_normal(const std::vector<Point3>& p, const Triangle& t) {
  return cross(sub(p[t[1]], p[t[0]]), sub(p[t[2]], p[t[0]]));  // length = 2 * area
}
inline double triangle_area(const std::vector<Point3>& p, const Triangle& t) {
  return 0.5 * norm(triangle_normal(p, t));
}
inline double total_area(const std::vector<Point3>& p, const std::vector<Triangle>& tris) {
  long double sum = 0;
  for (const auto& t : tris) sum += triangle_area(p, t);
  return static_cast<double>(sum);
}

// det[b-a, c-a, d-a] / 6.
inline double tet_volume(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  return dot(sub(b, a), cross(sub(c, a), sub(d, a))) / 6.0;
}
inline double total_tet_volume(const std::vector<Point3>& p, const std::vector<Tet>& tets) {
  long double sum = 0;
  for (const auto& t : tets) sum += tet_volume(p[t[0]], p[t[1]], p[t[2]], p[t[3]]);
  return static_cast<double>(sum);
}

// The oriented triangle rotated so its smallest vertex comes first.
inline Triangle canonical(const Triangle& t) {
  const int r = static_cast<int>(std::min_element(t.begin(), t.end()) - t.begin());
  return {t[r], t[(r + 1) % 3], t[(r + 2) % 3]};
}
inline std::multiset<Triangle> canonical_set(const std::vector<Triangle>& tris) {
  std::multiset<Triangle> s;
  for (const auto& t : tris) s.insert(canonical(t));
  return s;
}

// Every tet as its sorted ids, sorted: the same set of tets whatever their order and rotation.
inline std::vector<Tet> tet_set(const std::vector<Tet>& tets) {
  std::vector<Tet> set = tets;
  for (auto& t : set) std::sort(t.begin(), t.end());
  std::sort(set.begin(), set.end());
  return set;
}

// The mesh with its tets in another order (a fixed shuffle), neighbours and pieces following them.
inline TetMesh shuffled(const TetMesh& mesh, unsigned seed) {
  std::vector<std::int32_t> slot(mesh.tets.size());  // old tet -> new slot
  std::iota(slot.begin(), slot.end(), 0);
  std::shuffle(slot.begin(), slot.end(), std::mt19937(seed));
  TetMesh out = mesh;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    out.tets[slot[t]] = mesh.tets[t];
    if (!mesh.piece.empty()) out.piece[slot[t]] = mesh.piece[t];
    for (int j = 0; j < 4; ++j) {
      const std::int32_t nb = mesh.neighbours[t][j];
      out.neighbours[slot[t]][j] = nb < 0 ? -1 : slot[nb];
    }
  }
  return out;
}

// Empty when every directed edge occurs exactly once and its reverse exactly once (closed,
// edge-manifold, consistently oriented); otherwise a description of the first problem.
inline std::string closed_oriented_problem(const std::vector<Triangle>& tris) {
  std::map<std::pair<std::int32_t, std::int32_t>, int> count;
  for (const auto& t : tris)
    for (int e = 0; e < 3; ++e) ++count[{t[e], t[(e + 1) % 3]}];
  for (const auto& [edge, n] : count) {
    if (n != 1)
      return "directed edge " + std::to_string(edge.first) + "->" + std::to_string(edge.second) + " used " +
             std::to_string(n) + " times";
    auto it = count.find({edge.second, edge.first});
    if (it == count.end())
      return "directed edge " + std::to_string(edge.first) + "->" + std::to_string(edge.second) + " has no reverse";
  }
  return "";
}

// Border loops of an open triangulated region: the directed edges whose reverse is not in the
// set, chained into cycles. Returns the number of cycles (assumes each border vertex has one
// outgoing border edge, true for the caps in these tests).
inline int border_loop_count(const std::vector<Triangle>& tris) {
  std::set<std::pair<std::int32_t, std::int32_t>> edges;
  for (const auto& t : tris)
    for (int e = 0; e < 3; ++e) edges.insert({t[e], t[(e + 1) % 3]});
  std::map<std::int32_t, std::int32_t> next;
  for (const auto& e : edges)
    if (!edges.count({e.second, e.first})) next[e.first] = e.second;
  std::set<std::int32_t> visited;
  int loops = 0;
  for (const auto& [start, unused] : next) {
    (void)unused;
    if (visited.count(start)) continue;
    ++loops;
    std::int32_t v = start;
    while (!visited.count(v)) {
      visited.insert(v);
      auto it = next.find(v);
      if (it == next.end()) break;
      v = it->second;
    }
  }
  return loops;
}

// Connected components of the vertices used by a triangle set (vertex -> component id, -1 for
// unused vertices), components numbered by their smallest vertex.
inline std::vector<int> vertex_components(std::size_t point_count, const std::vector<Triangle>& tris) {
  std::vector<std::int32_t> parent(point_count);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](std::int32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::vector<char> used(point_count, 0);
  for (const auto& t : tris) {
    for (auto v : t) used[v] = 1;
    for (int e = 0; e < 2; ++e) {
      auto a = find(t[e]), b = find(t[e + 1]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  std::vector<int> comp(point_count, -1);
  std::map<std::int32_t, int> id;
  for (std::size_t v = 0; v < point_count; ++v) {
    if (!used[v]) continue;
    auto r = find(static_cast<std::int32_t>(v));
    auto it = id.find(r);
    if (it == id.end()) it = id.emplace(r, static_cast<int>(id.size())).first;
    comp[v] = it->second;
  }
  return comp;
}

// Area of the cross-section of the solid bounded by the closed, outward oriented `surface` with
// the plane x[axis] == offset, computed directly from the input triangles (shoelace over the
// crossing segments, oriented as a region with normal +axis). Cavities count negative, as in
// the solid. No vertex may lie on the plane.
inline double cross_section_area(const std::vector<Point3>& points, const std::vector<Triangle>& tris, int axis,
                                 double offset) {
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  long double twice_area = 0;
  for (const auto& t : tris) {
    // Crossing where the triangle's boundary leaves the part below the plane, and where it
    // comes back: the piece below traverses out -> in, its cap (normal +axis) in -> out.
    bool have_out = false, have_in = false;
    Point3 out{}, in{};
    for (int e = 0; e < 3; ++e) {
      const Point3& a = points[t[e]];
      const Point3& b = points[t[(e + 1) % 3]];
      const double sa = a[axis] - offset, sb = b[axis] - offset;
      if ((sa < 0) == (sb < 0)) continue;
      const double s = (offset - a[axis]) / (b[axis] - a[axis]);
      Point3 x;
      for (int i = 0; i < 3; ++i) x[i] = a[i] + s * (b[i] - a[i]);
      if (sa < 0) {
        out = x;
        have_out = true;
      } else {
        in = x;
        have_in = true;
      }
    }
    if (have_out && have_in)
      twice_area += static_cast<long double>(in[u]) * out[v] - static_cast<long double>(in[v]) * out[u];
  }
  return static_cast<double>(twice_area / 2);
}

// Signed area of a planar triangle projected to the plane with normal +axis (u, v the next two
// axes cyclically): positive when counter-clockwise seen from +axis.
inline double projected_area(const std::vector<Point3>& p, const Triangle& t, int axis) {
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  const Point3 &a = p[t[0]], &b = p[t[1]], &c = p[t[2]];
  return 0.5 * ((b[u] - a[u]) * (c[v] - a[v]) - (b[v] - a[v]) * (c[u] - a[u]));
}

// Index of the coordinate axis a unit coordinate normal points along, or -1.
inline int coordinate_axis_of(const Point3& n) {
  for (int i = 0; i < 3; ++i)
    if (n[i] == 1 && n[(i + 1) % 3] == 0 && n[(i + 2) % 3] == 0) return i;
  return -1;
}

// Faces of a tet mesh with no neighbour (oriented out of their tet).
inline std::vector<Triangle> open_faces(const TetMesh& mesh) {
  std::vector<Triangle> faces;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    for (int j = 0; j < 4; ++j)
      if (mesh.neighbours[t][j] < 0) faces.push_back(outward_face(mesh.tets[t], j));
  return faces;
}

// Empty when neighbours[t][j] is consistent for every tet: -1, or a tet that has the same face
// (the one opposite j in t) and points back at t through it; otherwise the first problem.
inline std::string neighbour_problem(const std::vector<Tet>& tets, const std::vector<Tet>& neighbours) {
  if (neighbours.size() != tets.size()) return "neighbour array has the wrong size";
  auto sorted = [](Triangle f) {
    std::sort(f.begin(), f.end());
    return f;
  };
  for (std::size_t t = 0; t < tets.size(); ++t)
    for (int j = 0; j < 4; ++j) {
      const auto u = neighbours[t][j];
      if (u < 0) continue;
      if (u >= static_cast<std::int32_t>(tets.size()) || u == static_cast<std::int32_t>(t))
        return "tet " + std::to_string(t) + " has an invalid neighbour " + std::to_string(u);
      const Triangle face = sorted(outward_face(tets[t], j));
      int back = -1;
      for (int i = 0; i < 4; ++i)
        if (sorted(outward_face(tets[u], i)) == face) back = i;
      if (back < 0) return "tets " + std::to_string(t) + " and " + std::to_string(u) + " share no face";
      if (neighbours[u][back] != static_cast<std::int32_t>(t))
        return "tet " + std::to_string(u) + " does not point back at " + std::to_string(t);
      // The two tets lie on opposite sides of the face: opposite orientations.
      if (canonical(outward_face(tets[t], j)) == canonical(outward_face(tets[u], back)))
        return "face oriented the same in both tets";
    }
  return "";
}

}  // namespace partet::test
