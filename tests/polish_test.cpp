// The quality polish: re-meshing the neighbourhoods of poor tets never makes the mesh's worst
// tet worse, keeps the solid (boundary, volume, adjacency) and leaves a failed neighbourhood as
// it was.
#include "stages/polish.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "stages/check.hpp"
#include "stages/generate.hpp"
#include "runner/piece_runner.hpp"
#include "job/pipeline.hpp"
#include "stages/quality.hpp"
#include "mesher/tetgen_mesher.hpp"
#include "stages/validate.hpp"
#include "stage_helpers.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

using namespace partet::test;

// The whole solid meshed by one TetGen run: input points first, then its Steiner points.
TetMesh whole_mesh(const SurfaceMesh& input, const std::string& quality) {
  TetgenOptions tetgen;
  tetgen.quality = quality;
  const LocalTetMesh local = mesh_closed_surface(input.points, input.triangles, tetgen);
  TetMesh mesh;
  mesh.points = input.points;
  mesh.points.insert(mesh.points.end(), local.steiner_points.begin(), local.steiner_points.end());
  mesh.tets = local.tets;
  mesh.neighbours = local.neighbours;
  return mesh;
}

// Meshes the neighbourhoods in this process, recording the optimization of each call.
PolishMesher here(const std::string& quality, std::vector<std::string>* optimizations = nullptr) {
  return [=](const std::vector<PieceSurface>& regions, const std::string& optimization) {
    if (optimizations) optimizations->push_back(optimization);
    TetgenOptions tetgen;
    tetgen.quality = quality;
    tetgen.optimization = optimization;
    RunOptions run;
    run.isolate = false;
    return mesh_pieces_here(regions, PieceRunner(tetgen, run));
  };
}

// Stricter bounds than the default, so that the small generated shapes have a few poor tets
// (5 to 15 here), apart as in a large mesh.
PolishOptions strict() {
  PolishOptions options;
  options.min_dihedral_deg = 8;
  options.max_amips = 12;
  return options;
}

TEST(Polish, NeverWorseAndKeepsTheSolid) {
  for (const char* name : {"genus3", "nested", "torus"}) {
    SCOPED_TRACE(name);
    const SurfaceMesh input = generate_surface(name, 3000);
    TetMesh mesh = whole_mesh(input, "1.414");
    const MeshQuality before = mesh_quality(mesh);
    const std::size_t tets_before = mesh.tets.size();
    std::vector<std::string> optimizations;
    const PolishStats stats = polish_poor_tets(mesh, strict(), here("1.414", &optimizations));
    const MeshQuality after = mesh_quality(mesh);

    EXPECT_GT(stats.poor_before, 0);
    EXPECT_LE(stats.poor_after, stats.poor_before);
    EXPECT_GT(stats.improved, 0);
    EXPECT_LE(stats.improved, stats.regions);
    EXPECT_EQ(mesh.tets.size(), tets_before - stats.tets_in + stats.tets_out);
    // The worst tet is never worse (up to rounding); the figures reported are the mesh's.
    EXPECT_GE(after.min_dihedral_deg, before.min_dihedral_deg - 1e-9);
    EXPECT_LE(after.amips_max, before.amips_max * (1 + 1e-9));
    EXPECT_NEAR(stats.min_dihedral_before, before.min_dihedral_deg, 1e-9);
    EXPECT_NEAR(stats.min_dihedral_after, after.min_dihedral_deg, 1e-9);
    EXPECT_NEAR(stats.amips_max_after, after.amips_max, 1e-9 * after.amips_max);
    // First with the pieces' switches, then with TetGen's thorough optimization.
    ASSERT_FALSE(optimizations.empty());
    EXPECT_EQ(optimizations.front(), "");
    for (std::size_t i = 1; i < optimizations.size(); ++i)
      if (optimizations[i] != "") EXPECT_EQ(optimizations[i], "9/7");

    // The same solid: input points first and unchanged, boundary = input, volume, adjacency.
    for (std::size_t v = 0; v < input.points.size(); ++v) ASSERT_EQ(mesh.points[v], input.points[v]);
    EXPECT_EQ(canonical_set(open_faces(mesh)), canonical_set(input.triangles));
    EXPECT_EQ(mesh.neighbours, compute_neighbours(mesh.tets));
    const double volume = enclosed_volume(input);
    EXPECT_NEAR(total_tet_volume(mesh.points, mesh.tets), volume, 1e-9 * volume);
    const std::vector<char> used = used_vertices(mesh.points.size(), mesh.tets);
    EXPECT_EQ(std::count(used.begin(), used.end(), 0), 0) << "unused points left";
    const CheckReport report = check_mesh(input, mesh);
    EXPECT_TRUE(report.ok());
  }
}

// The polish gives the same mesh whatever the order of the tets it is given: the same points in
// the same order, the same tets.
TEST(Polish, TheOrderOfTheTetsChangesNothing) {
  for (const char* name : {"genus3", "nested", "torus"}) {
    SCOPED_TRACE(name);
    TetMesh mesh = whole_mesh(generate_surface(name, 3000), "1.414");
    TetMesh other = shuffled(mesh, 11);
    const PolishStats a = polish_poor_tets(mesh, strict(), here("1.414"));
    const PolishStats b = polish_poor_tets(other, strict(), here("1.414"));
    EXPECT_GT(a.improved, 0);
    EXPECT_EQ(b.improved, a.improved);
    EXPECT_EQ(other.points, mesh.points);
    EXPECT_EQ(tet_set(other.tets), tet_set(mesh.tets));
    EXPECT_EQ(other.neighbours, compute_neighbours(other.tets));
  }
}

TEST(Polish, FailedNeighbourhoodsKeepTheirTets) {
  const SurfaceMesh input = generate_surface("genus3", 3000);
  TetMesh mesh = whole_mesh(input, "1.414");
  const TetMesh original = mesh;
  int calls = 0;
  const PolishMesher failing = [&](const std::vector<PieceSurface>& regions, const std::string&) {
    ++calls;
    std::vector<PieceOutcome> outcomes(regions.size());
    for (auto& o : outcomes) o.failure = Failure{};
    return outcomes;
  };
  const PolishStats stats = polish_poor_tets(mesh, strict(), failing);
  EXPECT_GT(stats.regions, 0);
  EXPECT_GT(calls, 1);  // a failed batch is tried again in halves
  EXPECT_EQ(stats.improved, 0);
  EXPECT_EQ(stats.poor_after, stats.poor_before);
  EXPECT_EQ(mesh.points, original.points);
  EXPECT_EQ(mesh.tets, original.tets);
  EXPECT_EQ(mesh.neighbours, original.neighbours);
}

TEST(Polish, NeighbourhoodsTooLargeOrTooPoorAreLeft) {
  // Poor tets in a large cluster are the input's shape, not a lottery: their neighbourhood is
  // not re-meshed at all (on a CAD part that cost 90% of the run for nothing).
  const SurfaceMesh input = generate_surface("genus3", 3000);
  const TetMesh original = whole_mesh(input, "1.414");
  for (int bound : {0, 1}) {
    SCOPED_TRACE(bound == 0 ? "largest_neighbourhood = 0" : "most_poor_tets = 0");
    PolishOptions options = strict();
    (bound == 0 ? options.largest_neighbourhood : options.most_poor_tets) = 0;
    TetMesh mesh = original;
    int calls = 0;
    const PolishStats stats =
        polish_poor_tets(mesh, options, [&](const std::vector<PieceSurface>&, const std::string&) {
          ++calls;
          return std::vector<PieceOutcome>();
        });
    EXPECT_EQ(calls, 0);
    EXPECT_GT(stats.poor_before, 0);
    EXPECT_EQ(stats.poor_after, stats.poor_before);
    EXPECT_EQ(stats.regions, 0);
    EXPECT_GT(stats.left, 0);
    EXPECT_EQ(mesh.tets, original.tets);
    EXPECT_EQ(mesh.points, original.points);
  }
  // With the default bounds this small mesh's neighbourhoods are all re-meshed.
  TetMesh mesh = original;
  const PolishStats stats = polish_poor_tets(mesh, strict(), here("1.414"));
  EXPECT_GT(stats.regions, 0);
  EXPECT_EQ(stats.left, 0);
}

TEST(Polish, NoPoorTetsNoWork) {
  const SurfaceMesh input = generate_surface("sphere", 1000);
  TetMesh mesh = whole_mesh(input, "1.414");
  const TetMesh original = mesh;
  PolishOptions lenient;
  lenient.min_dihedral_deg = 0;
  lenient.max_amips = std::numeric_limits<double>::infinity();
  int calls = 0;
  const PolishStats stats = polish_poor_tets(mesh, lenient, [&](const std::vector<PieceSurface>&, const std::string&) {
    ++calls;
    return std::vector<PieceOutcome>();
  });
  EXPECT_EQ(calls, 0);
  EXPECT_EQ(stats.poor_before, 0);
  EXPECT_EQ(mesh.tets, original.tets);
  EXPECT_NEAR(stats.min_dihedral_after, mesh_quality(mesh).min_dihedral_deg, 1e-9);
}

TEST(Polish, PipelinePolishesOnlyWithAQualityBound) {
  const SurfaceMesh input = generate_surface("genus3", 3000);
  MeshOptions options;
  options.pieces = 3;
  options.run.isolate = false;
  const MeshResult plain = mesh_surface(input, options);
  EXPECT_EQ(plain.polish.regions, 0);
  EXPECT_EQ(plain.polish.poor_before, 0);  // not even measured
  options.tetgen.quality = "1.414";
  const MeshResult refined = mesh_surface(input, options);
  EXPECT_LE(refined.polish.poor_after, refined.polish.poor_before);
  EXPECT_GE(refined.polish.min_dihedral_after, refined.polish.min_dihedral_before - 1e-9);
  const MeshQuality q = mesh_quality(refined.mesh);
  EXPECT_NEAR(q.min_dihedral_deg, refined.polish.min_dihedral_after, 1e-9);
  EXPECT_TRUE(check_mesh(input, refined.mesh).ok());
  options.polish = false;
  const MeshResult unpolished = mesh_surface(input, options);
  EXPECT_EQ(unpolished.polish.regions, 0);
  EXPECT_LE(q.amips_max, mesh_quality(unpolished.mesh).amips_max * (1 + 1e-9));
}

}  // namespace
}  // namespace partet
