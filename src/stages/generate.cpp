// Test surfaces built in code. Every shape is closed, manifold, outward oriented and free of
// self-intersections at any resolution. Each shell is turned by a fixed, non-axis-aligned
// rotation so that vertices do not line up on coordinate planes (which would make the
// partitioner's cut planes and TetGen's predicates hit many exact ties).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "stages/geometry.hpp"
#include "partet/errors.hpp"
#include "stages/generate.hpp"

namespace partet {
namespace {

using Matrix3 = std::array<std::array<double, 3>, 3>;

Matrix3 rotation(Point3 axis, double angle) {
  const double length = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  for (double& c : axis) c /= length;
  const double c = std::cos(angle), s = std::sin(angle), t = 1 - c;
  const double x = axis[0], y = axis[1], z = axis[2];
  return {{{t * x * x + c, t * x * y - s * z, t * x * z + s * y},
           {t * x * y + s * z, t * y * y + c, t * y * z - s * x},
           {t * x * z - s * y, t * y * z + s * x, t * z * z + c}}};
}

Point3 apply(const Matrix3& m, const Point3& p) {
  return {m[0][0] * p[0] + m[0][1] * p[1] + m[0][2] * p[2], m[1][0] * p[0] + m[1][1] * p[1] + m[1][2] * p[2],
          m[2][0] * p[0] + m[2][1] * p[1] + m[2][2] * p[2]};
}

// The rotation used for whole shapes; shells of multi-shell shapes get their own as well.
Matrix3 shape_rotation() { return rotation({1.0, 2.0, 3.0}, 0.4321); }

// Appends `part` to `surface`, rotated by `turn` and then moved by `offset`.
void append(SurfaceMesh& surface, const SurfaceMesh& part, const Matrix3& turn, const Point3& offset = {0, 0, 0}) {
  const auto base = static_cast<std::int32_t>(surface.points.size());
  for (const Point3& p : part.points) {
    Point3 q = apply(turn, p);
    surface.points.push_back({q[0] + offset[0], q[1] + offset[1], q[2] + offset[2]});
  }
  for (const Triangle& t : part.triangles) surface.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
}

void reverse_orientation(SurfaceMesh& surface) {
  for (Triangle& t : surface.triangles) std::swap(t[1], t[2]);
}

// The subdivision frequency n whose 20 n^2 faces come closest (by ratio) to the target.
int geodesic_frequency(double target_faces) {
  int n = std::max(1, static_cast<int>(std::sqrt(std::max(target_faces, 1.0) / 20)));
  auto error = [&](int k) { return std::abs(std::log(20.0 * k * k / target_faces)); };
  return error(n + 1) < error(n) ? n + 1 : n;
}

// A geodesic sphere: each face of an icosahedron split into n^2 triangles, with all points
// projected onto the sphere. Unlike a UV sphere it has no poles with slivers.
// The regular icosahedron (unnormalized corners, outward faces).
std::array<Point3, 12> icosahedron_corners() {
  const double phi = (1 + std::sqrt(5.0)) / 2;
  return {{{-1, phi, 0},
           {1, phi, 0},
           {-1, -phi, 0},
           {1, -phi, 0},
           {0, -1, phi},
           {0, 1, phi},
           {0, -1, -phi},
           {0, 1, -phi},
           {phi, 0, -1},
           {phi, 0, 1},
           {-phi, 0, -1},
           {-phi, 0, 1}}};
}
constexpr std::array<std::array<int, 3>, 20> kIcosahedronFaces = {
    {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
     {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
     {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}}};

SurfaceMesh geodesic_sphere(int n, double radius) {
  const std::array<Point3, 12> corners = icosahedron_corners();
  const auto& faces = kIcosahedronFaces;
  // Edge numbering, so that points on an icosahedron edge are shared by its two faces.
  std::array<std::array<int, 12>, 12> edge_id{};
  for (auto& row : edge_id) row.fill(-1);
  int edge_count = 0;
  for (const auto& f : faces)
    for (int c = 0; c < 3; ++c) {
      int a = std::min(f[c], f[(c + 1) % 3]), b = std::max(f[c], f[(c + 1) % 3]);
      if (edge_id[a][b] < 0) edge_id[a][b] = edge_count++;
    }

  const int interior_per_face = (n - 1) * (n - 2) / 2;
  SurfaceMesh sphere;
  sphere.points.assign(12 + 30 * (n - 1) + 20 * interior_per_face, Point3{0, 0, 0});
  auto project = [&](std::int32_t index, const Point3& p) {
    const double length = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    sphere.points[index] = {radius * p[0] / length, radius * p[1] / length, radius * p[2] / length};
  };
  for (int v = 0; v < 12; ++v) project(v, corners[v]);
  for (int a = 0; a < 12; ++a)
    for (int b = a + 1; b < 12; ++b) {
      if (edge_id[a][b] < 0) continue;
      for (int t = 1; t < n; ++t) {
        Point3 p;
        for (int i = 0; i < 3; ++i) p[i] = ((n - t) * corners[a][i] + t * corners[b][i]) / n;
        project(12 + edge_id[a][b] * (n - 1) + (t - 1), p);
      }
    }

  for (int f = 0; f < 20; ++f) {
    const auto& face = faces[f];
    // Point (a, b) of this face has weights (n - a - b, a, b) on its corners.
    auto index = [&](int a, int b) -> std::int32_t {
      const int weights[3] = {n - a - b, a, b};
      int nonzero[3], count = 0;
      for (int c = 0; c < 3; ++c)
        if (weights[c] > 0) nonzero[count++] = c;
      if (count == 1) return face[nonzero[0]];
      if (count == 2) {
        int u = face[nonzero[0]], v = face[nonzero[1]], weight_v = weights[nonzero[1]];
        if (u > v) {
          std::swap(u, v);
          weight_v = weights[nonzero[0]];
        }
        return 12 + edge_id[u][v] * (n - 1) + (weight_v - 1);
      }
      const int local = (a - 1) * (n - 1) - (a - 1) * a / 2 + (b - 1);
      return 12 + 30 * (n - 1) + f * interior_per_face + local;
    };
    for (int a = 1; a < n; ++a)
      for (int b = 1; a + b < n; ++b) {
        Point3 p;
        for (int i = 0; i < 3; ++i)
          p[i] = ((n - a - b) * corners[face[0]][i] + a * corners[face[1]][i] + b * corners[face[2]][i]) / n;
        project(index(a, b), p);
      }
    for (int a = 0; a < n; ++a)
      for (int b = 0; a + b < n; ++b) {
        sphere.triangles.push_back({index(a, b), index(a + 1, b), index(a, b + 1)});
        if (a + b + 2 <= n) sphere.triangles.push_back({index(a + 1, b), index(a + 1, b + 1), index(a, b + 1)});
      }
  }
  return sphere;
}

SurfaceMesh make_sphere(int faces) {
  SurfaceMesh surface;
  append(surface, geodesic_sphere(geodesic_frequency(faces), 1.0), shape_rotation());
  return surface;
}

// Torus with major radius 1 and tube radius 0.4 on a (major x minor) parameter grid, with the
// grid proportions following the radii so that quads stay close to square.
SurfaceMesh make_torus(int faces) {
  const double major_radius = 1.0, minor_radius = 0.4;
  const int minor = std::max(3, static_cast<int>(std::lround(std::sqrt(faces / 5.0))));
  const int major = std::max(6, static_cast<int>(std::lround(2.5 * minor)));
  SurfaceMesh torus;
  for (int i = 0; i < major; ++i)
    for (int j = 0; j < minor; ++j) {
      const double u = 2 * kPi * i / major, v = 2 * kPi * j / minor;
      const double ring = major_radius + minor_radius * std::cos(v);
      torus.points.push_back({ring * std::cos(u), ring * std::sin(u), minor_radius * std::sin(v)});
    }
  auto index = [&](int i, int j) { return (i % major) * minor + (j % minor); };
  // d/du x d/dv points outwards, so (u, v) -> (u+1, v) -> (u+1, v+1) is outward oriented.
  for (int i = 0; i < major; ++i)
    for (int j = 0; j < minor; ++j) {
      torus.triangles.push_back({index(i, j), index(i + 1, j), index(i + 1, j + 1)});
      torus.triangles.push_back({index(i, j), index(i + 1, j + 1), index(i, j + 1)});
    }
  SurfaceMesh surface;
  append(surface, torus, shape_rotation());
  return surface;
}

// A slab of 7 x 3 unit blocks with the three blocks (1,1), (3,1), (5,1) removed: genus 3.
// Each block is a cells x cells grid on top and bottom; the walls around the outline and the
// holes are split into layers of about the same size. Scaled to fit in [-1, 1]^3.
SurfaceMesh make_genus3(int faces) {
  constexpr int kBlocksX = 7, kBlocksY = 3;
  constexpr double kThickness = 0.5, kScale = 0.25;
  // 72 s^2 faces on top and bottom plus 64 s * layers on the walls, layers ~ s / 2.
  const int cells = std::max(1, static_cast<int>(std::lround(std::sqrt(faces / 104.0))));
  const int layers = std::max(1, static_cast<int>(std::lround(cells * kThickness)));
  const int nx = kBlocksX * cells, ny = kBlocksY * cells;

  auto solid = [&](int cx, int cy) {
    if (cx < 0 || cy < 0 || cx >= nx || cy >= ny) return false;
    const int bx = cx / cells, by = cy / cells;
    return !(by == 1 && bx % 2 == 1);
  };

  SurfaceMesh slab;
  // Vertices are created on first use so that points inside the holes do not exist at all.
  // wall[g][l] is the vertex of grid point g at layer l (0 = top, layers = bottom).
  std::vector<std::vector<std::int32_t>> wall((nx + 1) * (ny + 1));
  auto vertex = [&](int gx, int gy, int layer) {
    std::vector<std::int32_t>& column = wall[gy * (nx + 1) + gx];
    if (column.empty()) column.assign(layers + 1, -1);
    std::int32_t& id = column[layer];
    if (id < 0) {
      id = static_cast<std::int32_t>(slab.points.size());
      const double z = kThickness / 2 - kThickness * layer / layers;
      slab.points.push_back({kScale * (static_cast<double>(gx) / cells - kBlocksX / 2.0),
                             kScale * (static_cast<double>(gy) / cells - kBlocksY / 2.0), kScale * z});
    }
    return id;
  };

  for (int cy = 0; cy < ny; ++cy)
    for (int cx = 0; cx < nx; ++cx) {
      if (!solid(cx, cy)) continue;
      const std::int32_t t00 = vertex(cx, cy, 0), t10 = vertex(cx + 1, cy, 0), t11 = vertex(cx + 1, cy + 1, 0),
                         t01 = vertex(cx, cy + 1, 0);
      slab.triangles.push_back({t00, t10, t11});
      slab.triangles.push_back({t00, t11, t01});
      const std::int32_t b00 = vertex(cx, cy, layers), b10 = vertex(cx + 1, cy, layers),
                         b11 = vertex(cx + 1, cy + 1, layers), b01 = vertex(cx, cy + 1, layers);
      slab.triangles.push_back({b00, b11, b10});
      slab.triangles.push_back({b00, b01, b11});

      // The cell's outline counterclockwise seen from above, with the neighbour across each
      // side. A wall along a -> b runs from top to bottom and keeps the solid on its left.
      const int sides[4][6] = {{cx, cy, cx + 1, cy, cx, cy - 1},
                               {cx + 1, cy, cx + 1, cy + 1, cx + 1, cy},
                               {cx + 1, cy + 1, cx, cy + 1, cx, cy + 1},
                               {cx, cy + 1, cx, cy, cx - 1, cy}};
      for (const auto& side : sides) {
        if (solid(side[4], side[5])) continue;
        for (int l = 0; l < layers; ++l) {
          const std::int32_t b_upper = vertex(side[2], side[3], l), a_upper = vertex(side[0], side[1], l),
                             a_lower = vertex(side[0], side[1], l + 1), b_lower = vertex(side[2], side[3], l + 1);
          slab.triangles.push_back({b_upper, a_upper, a_lower});
          slab.triangles.push_back({b_upper, a_lower, b_lower});
        }
      }
    }
  SurfaceMesh surface;
  append(surface, slab, shape_rotation());
  return surface;
}

// Outer shell (radius 1), an inward-facing cavity (0.6) and an outward island (0.3), all
// centred at the origin. Distinct resolutions and rotations keep the shells' vertices apart.
// Even at the coarsest resolution an icosahedron's inradius (0.79 of its circumradius) keeps
// each shell clear of the next one inside.
SurfaceMesh make_nested(int faces) {
  SurfaceMesh surface;
  append(surface, geodesic_sphere(geodesic_frequency(0.5 * faces), 1.0), shape_rotation());
  SurfaceMesh cavity = geodesic_sphere(geodesic_frequency(0.3 * faces), 0.6);
  reverse_orientation(cavity);
  append(surface, cavity, rotation({-2.0, 1.0, 0.5}, 0.9876));
  append(surface, geodesic_sphere(geodesic_frequency(0.2 * faces), 0.3), rotation({0.3, -1.0, 2.0}, 1.2345));
  return surface;
}

// Two unit spheres 0.5 apart.
SurfaceMesh make_two_spheres(int faces) {
  const int n = geodesic_frequency(0.5 * faces);
  const Matrix3 turn = shape_rotation();
  SurfaceMesh surface;
  append(surface, geodesic_sphere(n, 1.0), turn, apply(turn, {-1.25, 0, 0}));
  append(surface, geodesic_sphere(n, 1.0), rotation({-2.0, 1.0, 0.5}, 0.9876), apply(turn, {1.25, 0, 0}));
  return surface;
}

struct ShapeMaker {
  const char* name;
  SurfaceMesh (*make)(int faces);
};

const ShapeMaker kShapes[] = {{"sphere", make_sphere},
                              {"torus", make_torus},
                              {"genus3", make_genus3},
                              {"nested", make_nested},
                              {"two_spheres", make_two_spheres}};

std::string known_shapes_text() {
  std::string text;
  for (const ShapeMaker& shape : kShapes) text += (text.empty() ? "" : ", ") + std::string(shape.name);
  return text;
}

}  // namespace

SurfaceMesh generate_surface(const std::string& shape, int faces) {
  if (faces < 1)
    throw OptionError("the target face count for a generated shape must be at least 1 (got " + std::to_string(faces) +
                      ")");
  for (const ShapeMaker& maker : kShapes)
    if (shape == maker.name) return maker.make(faces);
  throw OptionError("unknown shape '" + shape + "' (known: " + known_shapes_text() + ")");
}

std::vector<std::string> generated_shape_names() {
  std::vector<std::string> names;
  for (const ShapeMaker& shape : kShapes) names.push_back(shape.name);
  return names;
}

}  // namespace partet
