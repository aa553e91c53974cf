// The whole pipeline in one process: mesh_surface (with retries), verified by check_mesh.
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "job/pipeline.hpp"
#include "partet/errors.hpp"
#include "stage_batches.hpp"
#include "stage_helpers.hpp"
#include "stages/check.hpp"
#include "stages/generate.hpp"
#include "stages/topology.hpp"
#include "stages/validate.hpp"
#include "test_support.hpp"

namespace partet {
namespace {

using namespace partet::test;

MeshOptions options_for(int k, double density = 1.0) {
  MeshOptions o;
  o.pieces = k;
  o.density = density;
  o.run.isolate = false;  // faster; isolation is covered in tetgen_mesher_test
  return o;
}

std::string violations(const CheckReport& r) {
  std::string text;
  for (const auto& v : r.violations) text += v + "\n";
  return text;
}

// Meshes and checks; returns the result for further assertions.
MeshResult expect_meshes(const SurfaceMesh& input, const MeshOptions& options) {
  const MeshResult result = mesh_surface(input, options);
  const CheckReport report = check_mesh(input, result.mesh);
  EXPECT_TRUE(report.ok()) << violations(report);
  EXPECT_EQ(report.boundary_faces, static_cast<std::int64_t>(input.triangles.size()));
  EXPECT_NEAR(report.tet_volume, enclosed_volume(input), 1e-9 * enclosed_volume(input));
  EXPECT_EQ(result.seam.cut_vertices_removed, result.cut_vertices_inserted);
  if (options.pieces == 1) {
    EXPECT_EQ(result.cut_vertices_inserted, 0);
    EXPECT_EQ(result.cap_triangles, 0);
  }
  EXPECT_EQ(output_boundary(result, input), input.triangles);
  EXPECT_TRUE(result.boundary_faces.empty());  // every input vertex used: not copied
  EXPECT_EQ(canonical_set(open_faces(result.mesh)), canonical_set(input.triangles));
  EXPECT_EQ(neighbour_problem(result.mesh.tets, result.mesh.neighbours), "");
  return result;
}

// A mesh that may stay on its ranks is assembled for a check in memory only with the memory for it,
// and never with more tets than an assembled mesh can number (int32, with room for healing).
TEST(MeshSurface, AMeshIsAssembledToBeCheckedOnlyWhenItFits) {
  const double gb = 1e9;
  EXPECT_TRUE(assembles_to_check(8 * gb, 4 * gb, 20'000'000));
  EXPECT_FALSE(assembles_to_check(2 * gb, 4 * gb, 20'000'000));     // too little memory
  EXPECT_FALSE(assembles_to_check(8 * gb, 0, 20'000'000));          // no check asked for
  EXPECT_TRUE(assembles_to_check(1e6 * gb, 4 * gb, std::size_t{1} << 30));
  EXPECT_FALSE(assembles_to_check(1e6 * gb, 4 * gb, (std::size_t{1} << 30) + 1));  // checked in its files
  EXPECT_FALSE(assembles_to_check(1e6 * gb, 4 * gb, std::size_t{3} << 31));
}

TEST(MeshSurface, Sphere) {
  const SurfaceMesh s = generate_surface("sphere", 2000);
  for (int k : {1, 2, 3, 8}) {
    SCOPED_TRACE("k=" + std::to_string(k));
    const MeshResult r = expect_meshes(s, options_for(k));
    if (k > 1) {
      EXPECT_GT(r.cut_vertices_inserted, 0);
      EXPECT_GT(r.cap_triangles, 0);
    }
    EXPECT_TRUE(r.retries.empty());
  }
}

TEST(MeshSurface, TorusAllK) {
  const SurfaceMesh s = generate_surface("torus", 2000);
  for (int k : {1, 2, 3, 4, 8}) {
    SCOPED_TRACE("k=" + std::to_string(k));
    expect_meshes(s, options_for(k));
  }
}

TEST(MeshSurface, TorusCutThroughTheHole) {
  // The torus lies across its main axis, so the k = 2 plane passes through the hole: the cap
  // between the two pieces has two loops (two tube sections), and the pieces are two
  // U-shaped halves.
  const SurfaceMesh s = generate_surface("torus", 2000);
  const MeshOptions options = options_for(2);
  const PreparedPieces prepared = prepare_pieces(s, options);
  ASSERT_EQ(prepared.planes.size(), 1u);
  const int axis = coordinate_axis_of(prepared.planes[0].normal);
  ASSERT_GE(axis, 0);
  const double offset = prepared.planes[0].offset;
  // The plane passes through the middle (the hole's centre is at the origin).
  EXPECT_LT(std::abs(offset), 0.2);
  // The cap: the triangles of piece 0 lying on the plane.
  const PieceSurface& below = prepared.pieces[0];
  std::vector<Triangle> cap;
  for (const auto& t : below.triangles)
    if (below.points[t[0]][axis] == offset && below.points[t[1]][axis] == offset && below.points[t[2]][axis] == offset)
      cap.push_back(t);
  ASSERT_EQ(static_cast<std::int64_t>(cap.size()), prepared.cap_triangles);
  EXPECT_EQ(border_loop_count(cap), 2);
  // Each piece is one connected U, with genus 0 (V - E + F = 2).
  for (const auto& piece : prepared.pieces) {
    const auto comp = vertex_components(piece.points.size(), piece.triangles);
    EXPECT_EQ(*std::max_element(comp.begin(), comp.end()), 0);
    std::set<std::pair<std::int32_t, std::int32_t>> edges;
    for (const auto& t : piece.triangles)
      for (int e = 0; e < 3; ++e) edges.insert({std::min(t[e], t[(e + 1) % 3]), std::max(t[e], t[(e + 1) % 3])});
    EXPECT_EQ(static_cast<long>(piece.points.size()) - static_cast<long>(edges.size()) +
                  static_cast<long>(piece.triangles.size()),
              2);
  }
  expect_meshes(s, options);
}

TEST(MeshSurface, Genus3) {
  const SurfaceMesh s = generate_surface("genus3", 2000);
  for (int k : {1, 2, 5}) {
    SCOPED_TRACE("k=" + std::to_string(k));
    expect_meshes(s, options_for(k));
  }
}

TEST(MeshSurface, NestedCavityStaysEmpty) {
  const SurfaceMesh s = generate_surface("nested", 3000);
  const auto shell = vertex_components(s.points.size(), s.triangles);
  for (int k : {1, 2, 4}) {
    SCOPED_TRACE("k=" + std::to_string(k));
    // check_mesh compares the tet volume with outer - cavity + island.
    const MeshResult r = expect_meshes(s, options_for(k));
    for (const auto& t : r.mesh.tets) {
      std::set<int> shells;
      for (auto v : t)
        if (v < static_cast<std::int32_t>(s.points.size())) shells.insert(shell[v]);
      EXPECT_FALSE(shells.count(2) && shells.size() > 1) << "a tet joins the island to another shell";
    }
  }
}

TEST(MeshSurface, TwoSpheres) {
  const SurfaceMesh s = generate_surface("two_spheres", 2000);
  for (int k : {1, 2, 3, 4}) {
    SCOPED_TRACE("k=" + std::to_string(k));
    expect_meshes(s, options_for(k));
  }
}

TEST(MeshSurface, CapDensity) {
  const SurfaceMesh s = generate_surface("torus", 1500);
  std::size_t previous_points = 0;
  for (double density : {0.0, 2.0}) {
    SCOPED_TRACE("density " + std::to_string(density));
    const MeshResult r = expect_meshes(s, options_for(3, density));
    if (density == 0) {
      // Only input vertices (and any interior Steiner points TetGen needed).
      previous_points = r.mesh.points.size();
    } else {
      EXPECT_GT(r.mesh.points.size(), previous_points);
    }
  }
  expect_meshes(generate_surface("nested", 2000), options_for(2, 0.0));
  expect_meshes(generate_surface("nested", 2000), options_for(2, 2.0));
}

// Caps without interior points (--density 0) and no quality bound: no output vertex lies on a
// cut plane except input vertices (the planes are coordinate planes, so "on" is exact), and the
// mesh has about TetGen's own tets.
TEST(MeshSurface, CapsWithoutPointsLeaveNoPointOnACut) {
  for (const char* name : {"genus3", "nested"}) {
    SCOPED_TRACE(name);
    const SurfaceMesh s = generate_surface(name, 4000);
    const MeshResult r = expect_meshes(s, options_for(4, 0.0));
    ASSERT_EQ(r.planes.size(), 3u);
    EXPECT_EQ(r.seam.cap_points_removed, 0);
    for (std::size_t v = s.points.size(); v < r.mesh.points.size(); ++v)
      for (const CutPlane& plane : r.planes)
        EXPECT_NE(r.mesh.points[v][0] * plane.normal[0] + r.mesh.points[v][1] * plane.normal[1] +
                      r.mesh.points[v][2] * plane.normal[2],
                  plane.offset)
            << "output vertex " << v << " lies on a cut plane";
    const std::size_t tetgen_tets = mesh_closed_surface(s.points, s.triangles, TetgenOptions()).tets.size();
    EXPECT_LE(static_cast<double>(r.mesh.tets.size()), 1.05 * static_cast<double>(tetgen_tets));
  }
}

TEST(MeshSurface, PcaAxisAndQuality) {
  MeshOptions o = options_for(3);
  o.axis = CutAxis::pca;
  expect_meshes(generate_surface("genus3", 1500), o);
  expect_meshes(generate_surface("torus", 1500), o);
  MeshOptions q = options_for(3);
  q.tetgen.quality = "1.5";
  const MeshResult r = expect_meshes(generate_surface("sphere", 1000), q);
  EXPECT_GT(r.mesh.points.size(), generate_surface("sphere", 1000).points.size());
}

TEST(MeshSurface, TinyTetrahedronWithAnEdgeAcrossTwoPlanes) {
  SurfaceMesh s;
  s.points = {{0, 0, 0}, {10, 1, 0}, {10, 0, 1}, {20, 0.2, 0.3}};
  s.triangles = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  ASSERT_NO_THROW(validate_surface(s));
  for (int k : {1, 2, 3}) {
    SCOPED_TRACE("k=" + std::to_string(k));
    for (double density : {0.0, 1.0}) expect_meshes(s, options_for(k, density));
  }
}

TEST(MeshSurface, DeterministicAndIsolationIndependent) {
  const SurfaceMesh s = generate_surface("torus", 1500);
  MeshOptions o = options_for(4);
  const MeshResult a = mesh_surface(s, o);
  const MeshResult b = mesh_surface(s, o);
  o.run.isolate = true;
  const MeshResult c = mesh_surface(s, o);
  for (const MeshResult* r : {&b, &c}) {
    EXPECT_EQ(r->mesh.points, a.mesh.points);
    EXPECT_EQ(r->mesh.tets, a.mesh.tets);
    EXPECT_EQ(r->mesh.neighbours, a.mesh.neighbours);
  }
}

TEST(MeshSurface, StageTimesInOrder) {
  StageTimes times;
  mesh_surface(generate_surface("sphere", 500), options_for(2), &times);
  std::vector<std::string> names;
  for (const StageTime& t : times) {
    names.push_back(t.stage);
    EXPECT_GE(t.seconds, 0);
    EXPECT_GT(t.rss_mb, 0);
  }
  EXPECT_EQ(names, (std::vector<std::string>{"partition", "closure", "tetgen", "merge", "seam_healing"}));
}

TEST(MeshSurface, OptionErrorsAreThrownAtOnce) {
  const SurfaceMesh s = generate_surface("sphere", 300);
  EXPECT_THROW(mesh_surface(s, options_for(0)), OptionError);
  EXPECT_THROW(mesh_surface(s, options_for(2, -1.0)), OptionError);
}

// Balancing the estimated cost evens out the pieces' sizes, caps included, where the
// cross-sections differ (the genus-3 body is thick in the middle, thin at the ends), and the
// result still meshes and checks.
TEST(MeshSurface, BalanceCostEvensOutPieces) {
  const SurfaceMesh input = generate_surface("genus3", 20000);
  auto largest_over_mean = [](const PreparedPieces& p) {
    std::size_t largest = 0, sum = 0;
    for (const auto& piece : p.pieces)
      largest = std::max(largest, piece.triangles.size()), sum += piece.triangles.size();
    return static_cast<double>(largest) * static_cast<double>(p.pieces.size()) / static_cast<double>(sum);
  };
  MeshOptions options = options_for(6, 0.25);
  options.balance = Balance::vertices;
  const double by_vertices = largest_over_mean(prepare_pieces(input, options));
  options.balance = Balance::cost;
  const double by_cost = largest_over_mean(prepare_pieces(input, options));
  EXPECT_LT(by_cost, by_vertices);
  EXPECT_LT(by_cost, 1.10);
  expect_meshes(input, options);
}

TEST(MeshWithRetries, FailedPieceMovesItsPlanes) {
  const SurfaceMesh s = generate_surface("sphere", 1500);
  const MeshOptions o = options_for(4);
  int calls = 0;
  std::vector<std::vector<PieceSurface>> seen;
  const PieceMesher flaky = [&](const std::vector<PieceSurface>& pieces, const TetgenOptions& tetgen) {
    auto outcomes = mesh_pieces_here(pieces, PieceRunner(tetgen, o.run));
    if (!pieces.empty() && pieces.front().seam_region) return outcomes;  // the seams' round
    seen.push_back(pieces);
    if (calls++ == 0) {
      outcomes[1].result = {};
      outcomes[1].failure = Failure{FailureKind::tetgen_error, 1, {}, "simulated failure"};
    }
    return outcomes;
  };
  const MeshResult r = mesh_with_retries(s, o, flaky);
  EXPECT_EQ(calls, 2);
  ASSERT_EQ(r.retries.size(), 1u);
  EXPECT_EQ(r.retries[0].attempt, 0);
  EXPECT_EQ(r.retries[0].reason, "piece 1: simulated failure");
  EXPECT_EQ(r.retries[0].planes, (std::vector<int>{0, 1}));  // the planes bounding piece 1
  // The second partition differs from the first (moved planes), and the result is valid.
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_NE(seen[0][1].points, seen[1][1].points);
  // Piece 3 did not change: its first result is reused (its surface, freed once it was welded,
  // is built again from the failed attempt's planes for the comparison).
  ASSERT_EQ(seen[1].size(), 3u);
  EXPECT_EQ(seen[1][2].index, 2);
  const CheckReport report = check_mesh(s, r.mesh);
  EXPECT_TRUE(report.ok()) << violations(report);
}

TEST(MeshWithRetries, GivesUpAfterMaxAttempts) {
  const SurfaceMesh s = generate_surface("sphere", 500);
  MeshOptions o = options_for(3);
  o.max_attempts = 3;
  int calls = 0;
  const PieceMesher broken = [&](const std::vector<PieceSurface>& pieces, const TetgenOptions& tetgen) {
    ++calls;
    auto outcomes = mesh_pieces_here(pieces, PieceRunner(tetgen, o.run));
    if (!pieces.empty() && pieces.front().seam_region) return outcomes;
    outcomes.back().failure = Failure{FailureKind::tetgen_error, 2, {}, "always fails"};
    return outcomes;
  };
  try {
    mesh_with_retries(s, o, broken);
    ADD_FAILURE() << "no error";
  } catch (const MeshingError& e) {
    EXPECT_NE(std::string(e.what()).find("piece 2: always fails (after 3 partitions)"), std::string::npos) << e.what();
    EXPECT_EQ(e.failure.kind, FailureKind::tetgen_error);
    // The library names no command-line flags; the CLI adds that advice.
    EXPECT_EQ(std::string(e.what()).find("--"), std::string::npos) << e.what();
  }
  EXPECT_EQ(calls, 3);
}

// Every partition into pieces fails (a cut TetGen cannot recover, whatever the planes): the
// last resort is the whole input as one piece, as TetGen alone, and its mesh is valid.
TEST(MeshWithRetries, FallsBackToOnePieceWhenEveryCutFails) {
  const SurfaceMesh s = generate_thin_walls(ThinWallPart{"fins", 6, 1, 1, 0});
  const MeshOptions o = options_for(4, 0.25);
  std::vector<int> pieces_seen;
  const PieceMesher cuts_fail = [&](const std::vector<PieceSurface>& pieces, const TetgenOptions& tetgen) {
    auto outcomes = mesh_pieces_here(pieces, PieceRunner(tetgen, o.run));
    if (!pieces.empty() && pieces.front().seam_region) return outcomes;
    pieces_seen.push_back(static_cast<int>(pieces.size()));
    if (pieces.size() > 1)
      for (auto& outcome : outcomes) {
        outcome.result = {};
        outcome.failure = Failure{FailureKind::changed_boundary, 0, {}, "a cap cannot be recovered"};
      }
    return outcomes;
  };
  const MeshResult r = mesh_with_retries(s, o, cuts_fail);
  EXPECT_EQ(r.pieces, 1);
  EXPECT_GE(r.retries.size(), 2u);
  ASSERT_FALSE(pieces_seen.empty());
  EXPECT_EQ(pieces_seen.front(), 4);
  EXPECT_EQ(std::count(pieces_seen.begin(), pieces_seen.end(), 1), 1) << "one piece meshed once";
  const CheckReport report = check_mesh(s, r.mesh);
  EXPECT_TRUE(report.ok()) << violations(report);
  EXPECT_EQ(report.boundary_faces, static_cast<std::int64_t>(s.triangles.size()));
}

// The trouble is the input itself (the same input faces fail as one piece): said once, naming
// them, after one partition and one piece instead of every retry.
TEST(MeshWithRetries, InputTroubleIsNamedWithoutFutileRetries) {
  const SurfaceMesh s = generate_surface("sphere", 2000);
  const MeshOptions o = options_for(4, 0.25);
  std::set<FaceKey> input_faces;
  for (const Triangle& t : s.triangles) input_faces.insert(FaceKey(t));
  std::optional<FaceKey> bad;  // the first whole input face the first partition has
  int calls = 0;
  const PieceMesher input_fails = [&](const std::vector<PieceSurface>& pieces, const TetgenOptions& tetgen) {
    auto outcomes = mesh_pieces_here(pieces, PieceRunner(tetgen, o.run));
    if (!pieces.empty() && pieces.front().seam_region) return outcomes;
    ++calls;
    // The piece holding that face fails, naming it (in the piece's numbering), as TetGen would.
    for (std::size_t p = 0; p < pieces.size(); ++p)
      for (std::size_t t = 0; t < pieces[p].triangles.size(); ++t) {
        Triangle global;
        for (int c = 0; c < 3; ++c) global[c] = pieces[p].global_ids[pieces[p].triangles[t][c]];
        if (!bad && input_faces.count(FaceKey(global))) bad = FaceKey(global);
        if (bad && FaceKey(global) == *bad) {
          outcomes[p].result = {};
          outcomes[p].failure = Failure(FailureKind::changed_boundary, static_cast<int>(p), {},
                                        "TetGen changed the surface", {static_cast<std::int32_t>(t)});
        }
      }
    return outcomes;
  };
  try {
    mesh_with_retries(s, o, input_fails);
    ADD_FAILURE() << "no error";
  } catch (const MeshingError& e) {
    ASSERT_TRUE(bad);
    std::size_t face = 0;
    while (!(FaceKey(s.triangles[face]) == *bad)) ++face;
    EXPECT_NE(std::string(e.what()).find("without putting points on its surface (on input faces " +
                                         std::to_string(face) + ")"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(calls, 2);
}

// An input TetGen cannot mesh keeping its triangles whole (injected: every run that keeps them
// fails on an input triangle): without allow_split_faces the error names the faces and says that
// points on the surface may help; with it, the whole input is meshed as one piece, split triangles counted, and the
// check that allows split faces passes.
TEST(MeshWithRetries, SplitFacesOnlyWhenAllowedAndNeeded) {
  const SurfaceMesh s = generate_surface("torus", 320);  // TetGen -pq1.2 splits its triangles
  MeshOptions o = options_for(4, 0.25);
  o.tetgen.quality = "1.2";
  ::setenv("PARTET_INJECT_FAILURE", "surface", 1);
  try {
    mesh_surface(s, o);
    ADD_FAILURE() << "no error";
  } catch (const InputMeshingError& e) {
    EXPECT_TRUE(e.split_faces_may_help);
    EXPECT_TRUE(contains(e.what(), "without putting points on its surface (on input faces "));
    EXPECT_FALSE(contains(e.what(), "--allow-split-faces"));  // the CLI names its flags
  }
  o.allow_split_faces = true;
  const MeshResult r = mesh_surface(s, o);
  ::unsetenv("PARTET_INJECT_FAILURE");
  EXPECT_EQ(r.pieces, 1);
  EXPECT_GT(r.split_input_faces, 0);
  EXPECT_GT(r.surface_points_added, 0);
  ASSERT_LT(r.split_faces_from, r.boundary_faces.size());
  EXPECT_EQ(r.split_faces_from + r.split_input_faces, s.triangles.size());
  const CheckReport check = check_mesh(s, r.mesh, BoundaryRule::split_allowed);
  EXPECT_TRUE(check.ok()) << (check.ok() ? "" : check.violations.front());
  EXPECT_EQ(check.split_input_faces, r.split_input_faces);
  EXPECT_EQ(check.boundary_faces, static_cast<std::int64_t>(r.boundary_faces.size()));
  // Without the injected trouble the option changes nothing: the triangles stay whole.
  const MeshResult whole = mesh_surface(s, o);
  EXPECT_EQ(whole.split_input_faces, 0);
  EXPECT_EQ(whole.split_faces_from, SIZE_MAX);
  EXPECT_TRUE(check_mesh(s, whole.mesh).ok());
}

TEST(MeshPiecesHere, ReportsErrorsPerPiece) {
  PieceSurface bad;
  bad.index = 0;
  bad.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  bad.global_ids = {0, 1, 2};
  bad.triangles = {{0, 1, 2}};
  const auto outcomes = mesh_pieces_here({bad}, PieceRunner(TetgenOptions{}, RunOptions{false, 0}));
  ASSERT_EQ(outcomes.size(), 1u);
  ASSERT_TRUE(outcomes[0].failure);
  EXPECT_EQ(outcomes[0].failure->kind, FailureKind::bad_surface);
}

}  // namespace
}  // namespace partet
