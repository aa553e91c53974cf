#include "partet/tetgen_mesher.hpp"

#include <tetgen.h>

#include <string>
#include <unordered_map>
#include <vector>

#include "partet/errors.hpp"
#include "partet/face_key.hpp"
#include "partet/isolated_run.hpp"
#include "partet/serialize.hpp"
#include "partet/validate.hpp"

namespace partet {
namespace {

std::string tetgen_error_text(int code) {
  switch (code) {
    case 1: return "TetGen ran out of memory";
    case 2: return "TetGen hit an internal error";
    case 3: return "TetGen found a self-intersection";
    case 4: return "TetGen found a very small input feature (below its tolerance)";
    case 5: return "TetGen found two very close input facets";
    case 10: return "TetGen rejected the input";
    default: return "TetGen failed with code " + std::to_string(code);
  }
}

double orientation_sign(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  const double bx = b[0] - a[0], by = b[1] - a[1], bz = b[2] - a[2];
  const double cx = c[0] - a[0], cy = c[1] - a[1], cz = c[2] - a[2];
  const double dx = d[0] - a[0], dy = d[1] - a[1], dz = d[2] - a[2];
  return bx * (cy * dz - cz * dy) - by * (cx * dz - cz * dx) + bz * (cx * dy - cy * dx);
}

LocalTetMesh mesh_in_process(const std::vector<Point3>& points, const std::vector<Triangle>& triangles,
                             const TetgenOptions& options, int piece);

// Runs mesh_in_process in a child process (see IsolatedRun) and maps how it ended to errors.
LocalTetMesh mesh_in_child(const std::vector<Point3>& points, const std::vector<Triangle>& triangles,
                           const TetgenOptions& options, int piece) {
  const double limit =
      options.timeout_seconds > 0 ? options.timeout_seconds : default_tetgen_timeout(triangles.size(), options);
  IsolatedRun run(
      [&] {
        PieceTetMesh wrapped;
        wrapped.mesh = mesh_in_process(points, triangles, options, piece);
        return serialize_result(wrapped);
      },
      limit);
  run.wait();
  const IsolatedRun::Outcome outcome = run.outcome();
  if (outcome.ok) return deserialize_result(outcome.bytes).mesh;
  throw MeshingError(piece, strip_piece_prefix(outcome.message, piece, "TetGen "));
}

}  // namespace

double default_tetgen_timeout(std::size_t triangles, const TetgenOptions& options) {
  return (5.0 + 1e-3 * static_cast<double>(triangles)) * (options.quality.empty() ? 1 : 10);
}

std::string strip_piece_prefix(const std::string& message, int piece, const std::string& process_name) {
  // A message from inside the child names the piece already; one about how the child ended
  // ("crashed (signal 6 ...)") needs the name of what ran.
  const std::string prefix = "piece " + std::to_string(piece) + ": ";
  if (piece >= 0 && message.compare(0, prefix.size(), prefix) == 0) return message.substr(prefix.size());
  if (message.rfind("crashed", 0) == 0 || message.rfind("did not finish", 0) == 0 ||
      message.rfind("ended without", 0) == 0)
    return process_name + message;
  return message;
}

LocalTetMesh mesh_closed_surface(const std::vector<Point3>& points, const std::vector<Triangle>& triangles,
                                 const TetgenOptions& options, int piece) {
  if (options.isolate) return mesh_in_child(points, triangles, options, piece);
  return mesh_in_process(points, triangles, options, piece);
}

namespace {

LocalTetMesh mesh_in_process(const std::vector<Point3>& points, const std::vector<Triangle>& triangles,
                             const TetgenOptions& options, int piece) {
  const auto n = static_cast<std::int32_t>(points.size());
  if (triangles.empty()) throw MeshingError(piece, "empty surface");

  tetgenio in, out;
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

  // p: mesh a PLC; Y: no Steiner points on the boundary; z: 0-based; n: neighbours; Q: quiet.
  std::string switches = "pYzQn";
  if (!options.quality.empty()) switches += "q" + options.quality;
  try {
    tetrahedralize(switches.data(), &in, &out);
  } catch (int code) {
    throw MeshingError(piece, tetgen_error_text(code));
  }
  if (out.numberoftetrahedra <= 0 || out.tetrahedronlist == nullptr)
    throw MeshingError(piece, "TetGen produced no tetrahedra (is the surface closed?)");
  if (out.numberofpoints < n || out.neighborlist == nullptr)
    throw MeshingError(piece, "TetGen output is incomplete");
  for (std::int32_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c)
      if (out.pointlist[3 * static_cast<std::size_t>(i) + c] != points[i][c])
        throw MeshingError(piece, "TetGen moved input point " + std::to_string(i));

  const std::size_t tet_count = static_cast<std::size_t>(out.numberoftetrahedra);
  std::vector<Point3> all_points(points);
  for (int i = n; i < out.numberofpoints; ++i)
    all_points.push_back({out.pointlist[3 * i], out.pointlist[3 * i + 1], out.pointlist[3 * i + 2]});
  std::vector<Tet> tets(tet_count), neighbours(tet_count);
  for (std::size_t t = 0; t < tet_count; ++t)
    for (int j = 0; j < 4; ++j) {
      tets[t][j] = out.tetrahedronlist[4 * t + j];
      neighbours[t][j] = out.neighborlist[4 * t + j];
    }

  // TetGen orients all tets the same way; find which by a majority over well-shaped samples and
  // swap two corners when it is the opposite of ours (check_mesh verifies every tet exactly).
  long votes = 0;
  for (std::size_t t = 0; t < tet_count && t < 2000; ++t) {
    const auto& q = tets[t];
    const double s = orientation_sign(all_points[q[0]], all_points[q[1]], all_points[q[2]], all_points[q[3]]);
    votes += s > 0 ? 1 : (s < 0 ? -1 : 0);
  }
  if (votes < 0)
    for (std::size_t t = 0; t < tet_count; ++t) {
      std::swap(tets[t][0], tets[t][1]);
      std::swap(neighbours[t][0], neighbours[t][1]);
    }

  // Input faces split the tets into regions. A region is solid when its tets lie on the inner
  // side of the input triangles around it (winding number 1); cavities are dropped.
  std::unordered_map<FaceKey, std::int32_t, FaceKeyHash> input_face;
  input_face.reserve(triangles.size() * 2);
  for (std::size_t f = 0; f < triangles.size(); ++f)
    if (!input_face.emplace(FaceKey(triangles[f]), static_cast<std::int32_t>(f)).second)
      throw MeshingError(piece, "surface has a duplicate triangle");

  std::vector<std::int32_t> region(tet_count, -1);
  std::vector<std::int64_t> inside_votes, outside_votes;
  std::vector<std::size_t> stack;
  std::int32_t region_count = 0;
  for (std::size_t seed = 0; seed < tet_count; ++seed) {
    if (region[seed] != -1) continue;
    region[seed] = region_count;
    inside_votes.push_back(0);
    outside_votes.push_back(0);
    stack.push_back(seed);
    while (!stack.empty()) {
      const std::size_t t = stack.back();
      stack.pop_back();
      for (int j = 0; j < 4; ++j) {
        const Triangle face = outward_face(tets[t], j);
        auto it = input_face.find(FaceKey(face));
        if (it != input_face.end()) {
          // The input normal points out of the solid: a tet whose outward face agrees is inside.
          if (same_orientation(face, triangles[it->second]))
            ++inside_votes[region_count];
          else
            ++outside_votes[region_count];
          continue;
        }
        const auto nb = neighbours[t][j];
        if (nb >= 0 && region[nb] == -1) {
          region[nb] = region_count;
          stack.push_back(static_cast<std::size_t>(nb));
        }
      }
    }
    ++region_count;
  }

  std::vector<std::int32_t> new_index(tet_count, -1);
  LocalTetMesh result;
  for (std::size_t t = 0; t < tet_count; ++t) {
    const auto r = region[t];
    if (inside_votes[r] > 0 && outside_votes[r] > 0)
      throw MeshingError(piece, "a region of the mesh is both inside and outside the surface "
                                "(inconsistent orientation or overlapping shells)");
    if (inside_votes[r] > 0) {
      new_index[t] = static_cast<std::int32_t>(result.tets.size());
      result.tets.push_back(tets[t]);
    }
  }
  if (result.tets.empty()) throw MeshingError(piece, "no tetrahedra inside the surface (is it inside out?)");
  result.neighbours.reserve(result.tets.size());
  std::vector<char> seen(triangles.size(), 0);
  std::size_t boundary_faces = 0;
  for (std::size_t t = 0; t < tet_count; ++t) {
    if (new_index[t] < 0) continue;
    Tet nb;
    for (int j = 0; j < 4; ++j) {
      const auto old = neighbours[t][j];
      nb[j] = old >= 0 ? new_index[old] : -1;
      if (nb[j] >= 0) continue;
      // A face on the boundary of the kept tets must be one of the input triangles, outward.
      const Triangle face = outward_face(tets[t], j);
      auto it = input_face.find(FaceKey(face));
      if (it == input_face.end() || !same_orientation(face, triangles[it->second]) || seen[it->second])
        throw MeshingError(piece, "TetGen changed the surface (a boundary face is not an input triangle)");
      seen[it->second] = 1;
      ++boundary_faces;
    }
    result.neighbours.push_back(nb);
  }
  if (boundary_faces != triangles.size())
    throw MeshingError(piece, "TetGen changed the surface: " + std::to_string(triangles.size() - boundary_faces) +
                                  " input triangles are not faces of the mesh");

  // Interior Steiner points that ended up used by kept tets only.
  std::vector<std::int32_t> point_index(all_points.size(), -1);
  for (std::int32_t i = 0; i < n; ++i) point_index[i] = i;
  std::int32_t next = n;
  for (auto& t : result.tets)
    for (auto& v : t) {
      if (point_index[v] < 0) {
        point_index[v] = next++;
        result.steiner_points.push_back(all_points[v]);
      }
      v = point_index[v];
    }
  return result;
}

}  // namespace

PieceTetMesh tetrahedralize_piece(const PieceSurface& piece, const TetgenOptions& options) {
  // Checks and mesh in one child process (which runs this function again, not isolated), so the
  // checks run once and the result crosses the process boundary once.
  if (options.isolate) return deserialize_result(tetrahedralize_piece_to_bytes(piece, options));
  check_piece_topology(piece);
  const SurfaceMesh surface{piece.points, piece.triangles};
  try {
    check_no_self_intersections(surface, ("piece " + std::to_string(piece.index)).c_str());
  } catch (const InputError& e) {
    throw MeshingError(-1, std::string(e.what()) + " (the input self-intersects, or a cut is too close to a feature)");
  }
  PieceTetMesh result;
  result.index = piece.index;
  result.surface_point_count = static_cast<std::int32_t>(piece.points.size());
  result.mesh = mesh_closed_surface(piece.points, piece.triangles, options, piece.index);
  return result;
}

std::unique_ptr<IsolatedRun> start_piece_meshing(const PieceSurface& piece, const TetgenOptions& options,
                                                 const std::function<void()>& before) {
  TetgenOptions in_child = options;
  in_child.isolate = false;  // the whole piece already runs in the child
  const double limit = options.timeout_seconds > 0
                           ? options.timeout_seconds
                           : 10 + default_tetgen_timeout(piece.triangles.size(), options);
  return std::make_unique<IsolatedRun>(
      [&piece, in_child, before] {
        if (before) before();
        return serialize_result(tetrahedralize_piece(piece, in_child));
      },
      limit);
}

std::string piece_meshing_result(IsolatedRun& run, int piece) {
  run.wait();
  IsolatedRun::Outcome outcome = run.outcome();
  if (!outcome.ok) throw MeshingError(piece, strip_piece_prefix(outcome.message, piece, "meshing "));
  return std::move(outcome.bytes);
}

std::string tetrahedralize_piece_to_bytes(const PieceSurface& piece, const TetgenOptions& options) {
  if (!options.isolate) return serialize_result(tetrahedralize_piece(piece, options));
  auto run = start_piece_meshing(piece, options);
  return piece_meshing_result(*run, piece.index);
}

}  // namespace partet
