#include "mesher/tetgen_mesher.hpp"

#include <tetgen.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <string>
#include <unordered_map>
#include <vector>

#include "partet/errors.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

// TetGen's error codes (thrown as int through our terminatetetgen).
MeshingError tetgen_error(int code, int piece) {
  switch (code) {
    case 1:
      return MeshingError(FailureKind::tetgen_error, piece, kTetgenOutOfMemory);
    case 2:
      return MeshingError(FailureKind::tetgen_error, piece, "TetGen hit an internal error");
    case 3:
      return MeshingError(FailureKind::self_intersection, piece, "TetGen found a self-intersection");
    case 4:
      return MeshingError(FailureKind::tetgen_error, piece,
                          "TetGen found a very small input feature (below its tolerance)");
    case 5:
      return MeshingError(FailureKind::tetgen_error, piece, "TetGen found two very close input facets");
    case 10:
      return MeshingError(FailureKind::tetgen_error, piece, "TetGen rejected the input");
    default:
      return MeshingError(FailureKind::tetgen_error, piece, "TetGen failed with code " + std::to_string(code));
  }
}

// Only decides which way TetGen orients its tets, by a vote over many; check_mesh verifies every
// tet with an exact predicate, independently.
double orientation_sign(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  const double bx = b[0] - a[0], by = b[1] - a[1], bz = b[2] - a[2];
  const double cx = c[0] - a[0], cy = c[1] - a[1], cz = c[2] - a[2];
  const double dx = d[0] - a[0], dy = d[1] - a[1], dz = d[2] - a[2];
  return bx * (cy * dz - cz * dy) - by * (cx * dz - cz * dx) + bz * (cx * dy - cy * dx);
}

// A TetGen result as plain arrays, in our orientation.
struct RawMesh {
  std::vector<Point3> points;  // the surface's points, then TetGen's Steiner points
  std::vector<Tet> tets, neighbours;
  // With points on the surface allowed: TetGen's boundary faces, each with the input triangle
  // (facet) it lies in.
  std::vector<std::pair<Triangle, std::int32_t>> subfaces;
};

void fill_tetgen_input(const std::vector<Point3>& points, const std::vector<Triangle>& triangles, tetgenio& in) {
  const auto n = static_cast<std::int32_t>(points.size());
  in.firstnumber = 0;
  in.numberofpoints = n;
  in.pointlist = new REAL[3 * static_cast<std::size_t>(n)];
  for (std::int32_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) in.pointlist[3 * static_cast<std::size_t>(i) + c] = points[i][c];
  in.numberoffacets = static_cast<int>(triangles.size());
  in.facetlist = new tetgenio::facet[triangles.size()];
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    tetgenio::facet& facet = in.facetlist[f];
    tetgenio::init(&facet);
    facet.numberofpolygons = 1;
    facet.polygonlist = new tetgenio::polygon[1];
    tetgenio::init(&facet.polygonlist[0]);
    facet.polygonlist[0].numberofvertices = 3;
    facet.polygonlist[0].vertexlist = new int[3]{triangles[f][0], triangles[f][1], triangles[f][2]};
  }
}

// Runs TetGen and copies its output, after checking that it kept the input points.
RawMesh run_tetgen(const std::vector<Point3>& points, const std::vector<Triangle>& triangles,
                   const TetgenOptions& options, int piece) {
  tetgenio in, out;
  fill_tetgen_input(points, triangles, in);
  // p: mesh a PLC; Y: no Steiner points on the boundary; z: 0-based; n: neighbours; Q: quiet.
  std::string switches = options.boundary_points ? "pzQn" : "pYzQn";
  if (options.boundary_points) {
    // Each triangle its own facet marker, so that every boundary face names the one it lies in.
    in.facetmarkerlist = new int[triangles.size()];
    for (std::size_t f = 0; f < triangles.size(); ++f) in.facetmarkerlist[f] = static_cast<int>(f) + 1;
  }
  if (!options.quality.empty()) switches += "q" + options.quality;
  if (!options.tolerance.empty()) switches += "T" + options.tolerance;
  if (!options.optimization.empty()) switches += "O" + options.optimization;
  try {
    tetrahedralize(switches.data(), &in, &out);
  } catch (int code) {
    throw tetgen_error(code, piece);
  }
  const auto n = static_cast<std::int32_t>(points.size());
  if (out.numberoftetrahedra <= 0 || out.tetrahedronlist == nullptr)
    throw MeshingError(FailureKind::tetgen_error, piece,
                       "TetGen produced no tetrahedra for this closed surface (it gave up without an error)");
  if (out.numberofpoints < n)
    throw MeshingError(FailureKind::too_close, piece, "TetGen merged input points closer than its tolerance");
  if (out.neighborlist == nullptr) throw MeshingError(FailureKind::tetgen_error, piece, "TetGen output is incomplete");
  for (std::int32_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c)
      if (out.pointlist[3 * static_cast<std::size_t>(i) + c] != points[i][c])
        throw MeshingError(FailureKind::changed_boundary, piece, "TetGen moved input point " + std::to_string(i));

  RawMesh raw;
  raw.points = points;
  for (int i = n; i < out.numberofpoints; ++i)
    raw.points.push_back({out.pointlist[3 * i], out.pointlist[3 * i + 1], out.pointlist[3 * i + 2]});
  const std::size_t tet_count = static_cast<std::size_t>(out.numberoftetrahedra);
  raw.tets.resize(tet_count);
  raw.neighbours.resize(tet_count);
  for (std::size_t t = 0; t < tet_count; ++t)
    for (int j = 0; j < 4; ++j) {
      raw.tets[t][j] = out.tetrahedronlist[4 * t + j];
      raw.neighbours[t][j] = out.neighborlist[4 * t + j];
    }
  if (options.boundary_points) {
    if (out.trifacelist == nullptr || out.trifacemarkerlist == nullptr)
      throw MeshingError(FailureKind::tetgen_error, piece, "TetGen output has no boundary faces");
    for (int f = 0; f < out.numberoftrifaces; ++f)
      raw.subfaces.push_back({{out.trifacelist[3 * f], out.trifacelist[3 * f + 1], out.trifacelist[3 * f + 2]},
                              out.trifacemarkerlist[f] - 1});
  }
  return raw;
}

// TetGen orients all tets the same way; find which by a majority over well-shaped samples and
// swap two corners when it is the opposite of ours.
void orient_positively(RawMesh& raw) {
  long votes = 0;
  for (std::size_t t = 0; t < raw.tets.size() && t < 2000; ++t) {
    const auto& q = raw.tets[t];
    const double s = orientation_sign(raw.points[q[0]], raw.points[q[1]], raw.points[q[2]], raw.points[q[3]]);
    votes += s > 0 ? 1 : (s < 0 ? -1 : 0);
  }
  if (votes < 0)
    for (std::size_t t = 0; t < raw.tets.size(); ++t) {
      std::swap(raw.tets[t][0], raw.tets[t][1]);
      std::swap(raw.neighbours[t][0], raw.neighbours[t][1]);
    }
}

// Connected components of the surface, triangles joined across shared edges.
std::size_t shell_count(const std::vector<Triangle>& triangles) {
  DisjointSets shells(0, triangles.size());
  // Each undirected edge, with the triangle that used it first.
  std::vector<std::pair<std::uint64_t, std::int32_t>> edges;
  edges.reserve(triangles.size() * 3);
  for (std::size_t f = 0; f < triangles.size(); ++f)
    for (int e = 0; e < 3; ++e) {
      const auto a = static_cast<std::uint32_t>(std::min(triangles[f][e], triangles[f][(e + 1) % 3]));
      const auto b = static_cast<std::uint32_t>(std::max(triangles[f][e], triangles[f][(e + 1) % 3]));
      edges.push_back({std::uint64_t{a} << 32 | b, static_cast<std::int32_t>(f)});
    }
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 1; i < edges.size(); ++i)
    if (edges[i].first == edges[i - 1].first) shells.join(edges[i].second, edges[i - 1].second);
  std::size_t components = 0;
  for (std::size_t f = 0; f < shells.size(); ++f)
    if (shells.find(static_cast<std::int32_t>(f)) == static_cast<std::int32_t>(f)) ++components;
  return components;
}

// The faces that may bound the mesh, each with the input triangle it lies in, and how to tell
// whether a tet's outward face there faces the same way as that triangle.
struct InputFaces {
  std::unordered_map<FaceKey, std::int32_t, FaceKeyHash> triangle_of;
  bool split = false;  // faces may be parts of input triangles (points on the surface allowed)
  const std::vector<Point3>* points = nullptr;
  const std::vector<Triangle>* triangles = nullptr;

  // The input triangle the face lies in, or -1.
  std::int32_t find(const Triangle& face) const {
    auto it = triangle_of.find(FaceKey(face));
    return it == triangle_of.end() ? -1 : it->second;
  }
  bool agrees(const Triangle& face, std::int32_t input) const {
    const Triangle& t = (*triangles)[input];
    if (!split || FaceKey(face) == FaceKey(t)) return same_orientation(face, t);
    // A part of the triangle, in its plane: the normals are parallel, the sign is all that counts.
    const auto normal = [&](const Triangle& f) {
      const Point3 &a = (*points)[f[0]], &b = (*points)[f[1]], &c = (*points)[f[2]];
      const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      return Point3{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    };
    const Point3 n = normal(face), m = normal(t);
    return n[0] * m[0] + n[1] * m[1] + n[2] * m[2] > 0;
  }
};

InputFaces index_input_faces(const std::vector<Triangle>& triangles, const RawMesh& raw, bool split, int piece) {
  InputFaces faces{{}, split, &raw.points, &triangles};
  faces.triangle_of.reserve(triangles.size() * 2);
  for (std::size_t f = 0; f < triangles.size(); ++f)
    if (!faces.triangle_of.emplace(FaceKey(triangles[f]), static_cast<std::int32_t>(f)).second)
      throw MeshingError(FailureKind::bad_surface, piece, "surface has a duplicate triangle");
  if (split)
    for (const auto& [face, input] : raw.subfaces)
      if (input >= 0 && static_cast<std::size_t>(input) < triangles.size()) faces.triangle_of.emplace(FaceKey(face), input);
  return faces;
}

// Input faces split the tets into regions. A region is solid when its tets lie on the inner
// side of the input triangles around it (winding number 1); cavities are not. Returns, per tet,
// whether it is solid.
std::vector<char> solid_tets(const RawMesh& raw, const InputFaces& input_face, int piece) {
  std::vector<std::int32_t> region;
  const std::int32_t region_count = label_tet_regions(
      raw.neighbours, [](std::size_t) { return true; },
      [&](std::size_t t, int j) { return input_face.find(outward_face(raw.tets[t], j)) < 0; }, region);
  std::vector<std::int64_t> inside_votes(region_count, 0), outside_votes(region_count, 0);
  for (std::size_t t = 0; t < raw.tets.size(); ++t)
    for (int j = 0; j < 4; ++j) {
      const Triangle face = outward_face(raw.tets[t], j);
      const std::int32_t input = input_face.find(face);
      if (input < 0) continue;
      // The input normal points out of the solid: a tet whose outward face agrees is inside.
      ++(input_face.agrees(face, input) ? inside_votes : outside_votes)[region[t]];
    }
  std::vector<char> solid(raw.tets.size(), 0);
  for (std::size_t t = 0; t < raw.tets.size(); ++t) {
    const auto r = region[t];
    if (inside_votes[r] > 0 && outside_votes[r] > 0)
      throw MeshingError(FailureKind::bad_surface, piece,
                         "a region of the mesh is both inside and outside the surface "
                         "(inconsistent orientation or overlapping shells)");
    solid[t] = inside_votes[r] > 0;
  }
  return solid;
}

// The solid tets, renumbered, with the Steiner points they use. A face on the boundary of the
// kept tets must be one of the input triangles, outward, and every input triangle must be one
// (with split faces: lie in one, facing the same way, and every input triangle must hold one).
LocalTetMesh keep_solid_tets(const RawMesh& raw, const std::vector<char>& solid, const std::vector<Triangle>& triangles,
                             const InputFaces& input_face, int piece) {
  const std::vector<std::int32_t> new_index = compact_ids(solid);
  LocalTetMesh result;
  for (std::size_t t = 0; t < raw.tets.size(); ++t)
    if (solid[t]) result.tets.push_back(raw.tets[t]);
  if (result.tets.empty())
    throw MeshingError(FailureKind::bad_surface, piece, "no tetrahedra inside the surface (is it inside out?)");
  result.neighbours.reserve(result.tets.size());
  std::vector<char> seen(triangles.size(), 0);
  std::size_t boundary_faces = 0, foreign_faces = 0;
  for (std::size_t t = 0; t < raw.tets.size(); ++t) {
    if (!solid[t]) continue;
    Tet nb;
    for (int j = 0; j < 4; ++j) {
      const auto old = raw.neighbours[t][j];
      nb[j] = old >= 0 ? new_index[old] : -1;
      if (nb[j] >= 0) continue;
      const Triangle face = outward_face(raw.tets[t], j);
      const std::int32_t input = input_face.find(face);
      if (input < 0 || !input_face.agrees(face, input) || (seen[input] && !input_face.split)) {
        ++foreign_faces;
        continue;
      }
      boundary_faces += seen[input] ? 0 : 1;
      seen[input] = 1;
    }
    result.neighbours.push_back(nb);
  }
  if (foreign_faces > 0 || boundary_faces != triangles.size()) {
    // The input triangles TetGen split (or lost): what a message can name.
    std::vector<std::int32_t> missing;
    for (std::size_t f = 0; f < triangles.size(); ++f)
      if (!seen[f]) missing.push_back(static_cast<std::int32_t>(f));
    throw MeshingError(Failure(FailureKind::changed_boundary, piece, {},
                               "TetGen changed the surface: " + std::to_string(missing.size()) +
                                   " triangles are not faces of its mesh (it needed points on them)",
                               missing));
  }
  return result;
}

// Renumbers the Steiner points used by the kept tets in order of first use, after the surface's.
void keep_used_steiner_points(LocalTetMesh& mesh, const std::vector<Point3>& all_points, std::int32_t surface_count) {
  std::vector<std::int32_t> point_index(all_points.size(), -1);
  for (std::int32_t i = 0; i < surface_count; ++i) point_index[i] = i;
  std::int32_t next = surface_count;
  for (auto& t : mesh.tets)
    for (auto& v : t) {
      if (point_index[v] < 0) {
        point_index[v] = next++;
        mesh.steiner_points.push_back(all_points[v]);
      }
      v = point_index[v];
    }
}

// A plain decimal number: digits, at most one point, an optional exponent. No sign, inf, nan or
// hexadecimal: what TetGen's switch parser reads the same way.
bool parse_plain_number(const std::string& text, double& value) {
  std::size_t i = 0, digits = 0;
  while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i, ++digits;
  if (i < text.size() && text[i] == '.') {
    ++i;
    while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i, ++digits;
  }
  if (digits == 0) return false;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
    const std::size_t start = i;
    while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i;
    if (i == start) return false;
  }
  if (i != text.size()) return false;
  value = std::strtod(text.c_str(), nullptr);
  return std::isfinite(value);
}

}  // namespace

std::string parse_quality(const std::string& text) {
  if (text.empty()) return text;
  const std::size_t slash = text.find('/');
  double ratio = 0, angle = 0;
  const bool ok = parse_plain_number(text.substr(0, slash), ratio) && ratio >= 1 && ratio <= 100 &&
                  (slash == std::string::npos || (parse_plain_number(text.substr(slash + 1), angle) && angle <= 20));
  if (!ok)
    throw OptionError("the quality bound must be R or R/ANGLE with 1 <= R <= 100 and 0 <= ANGLE <= 20 degrees (got '" +
                      text + "')");
  return text;
}

LocalTetMesh mesh_closed_surface(const std::vector<Point3>& points, const std::vector<Triangle>& triangles,
                                 const TetgenOptions& options, int piece, SurfaceRegions regions) {
  if (triangles.empty()) throw MeshingError(FailureKind::bad_surface, piece, "empty surface");
  RawMesh raw = run_tetgen(points, triangles, options, piece);
  orient_positively(raw);
  const InputFaces input_face = index_input_faces(triangles, raw, options.boundary_points, piece);
  // TetGen removes the tets outside the outermost surface itself, so inside a single manifold
  // shell every tet is solid; otherwise regions are told apart by orientation.
  const std::vector<char> solid = regions == SurfaceRegions::one_shell ? std::vector<char>(raw.tets.size(), 1)
                                                                       : solid_tets(raw, input_face, piece);
  LocalTetMesh result = keep_solid_tets(raw, solid, triangles, input_face, piece);
  keep_used_steiner_points(result, raw.points, static_cast<std::int32_t>(points.size()));
  return result;
}

PieceTetMesh tetrahedralize_piece(const PieceSurface& piece, const TetgenOptions& options) {
  // Self-intersections are left to TetGen: a tet mesh that has every triangle of the piece as a
  // face proves they do not intersect, and when TetGen fails the pipeline checks the whole
  // input before blaming the cuts. The topology check is cheap and catches a partition bug
  // before TetGen sees it.
  if (!piece.seam_region) check_piece_topology(piece);
  PieceTetMesh result;
  result.index = piece.index;
  result.surface_point_count = static_cast<std::int32_t>(piece.points.size());
  // A piece is manifold (the input was validated, the caps close it); with one shell it
  // encloses one region.
  const SurfaceRegions regions =
      !piece.seam_region && shell_count(piece.triangles) == 1 ? SurfaceRegions::one_shell : SurfaceRegions::any;
  result.mesh = mesh_closed_surface(piece.points, piece.triangles, options, piece.index, regions);
  return result;
}

}  // namespace partet
