// Seam healing: after heal_seams (and finish_mesh around it) the mesh has no cut vertex (and,
// when healing, no cap point), every input triangle is a boundary face, and check_mesh accepts it.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "job/pipeline.hpp"
#include "partet/errors.hpp"
#include "stage_batches.hpp"
#include "stage_helpers.hpp"
#include "test_support.hpp"
#include "stages/check.hpp"
#include "stages/generate.hpp"
#include "stages/merge.hpp"
#include "stages/seam_healing.hpp"
#include "stages/tet_region.hpp"
#include "stages/topology.hpp"
#include "stages/validate.hpp"

namespace partet {
namespace {

using namespace partet::test;

using Stage = MeshedPieces;

Stage prepare(const SurfaceMesh& input, int k, double density = 1.0, const std::string& quality = "") {
  return mesh_pieces_in_batch(input, k, density, quality);
}

RegionMesher here(const MeshOptions& options) { return regions_here(options); }

std::string violations(const CheckReport& r) {
  std::string text;
  for (const auto& v : r.violations) text += v + "\n";
  return text;
}

// The properties of the final mesh of `input` (all input vertices used).
void expect_clean_result(const SurfaceMesh& input, const Stage& s, const MeshResult& result) {
  const TetMesh& mesh = result.mesh;
  const SplitSurface& split = s.prepared.split;
  EXPECT_EQ(result.seam.cut_vertices_removed, split.cut_vertex_count());
  if (split.cut_vertex_count() > 0) {
    EXPECT_GT(result.seam.tets_in, 0);
    EXPECT_GT(result.seam.tets_out, 0);
  }
  // Healing removes the caps' interior points too.
  if (heals(s.options))
    EXPECT_EQ(result.seam.cap_points_removed, static_cast<std::int64_t>(split.cap_point_plane.size()));
  // Input vertices first, same order and coordinates.
  ASSERT_GE(mesh.points.size(), input.points.size());
  for (std::size_t v = 0; v < input.points.size(); ++v) ASSERT_EQ(mesh.points[v], input.points[v]);
  // No cut vertex coordinate survives; later points are strictly interior.
  std::set<Point3> cut;
  for (std::int32_t c = 0; c < split.cut_vertex_count(); ++c) cut.insert(split.points[split.input_vertex_count + c]);
  for (const auto& p : mesh.points) EXPECT_FALSE(cut.count(p)) << "a cut vertex is still in the mesh";
  // The boundary is exactly the input triangles (output numbering = input numbering here), so
  // the only boundary vertices are input vertices.
  EXPECT_EQ(output_boundary(result, input), input.triangles);
  EXPECT_EQ(canonical_set(open_faces(mesh)), canonical_set(input.triangles));
  for (const auto& f : open_faces(mesh))
    for (auto v : f) EXPECT_LT(v, static_cast<std::int32_t>(input.points.size()));
  EXPECT_EQ(neighbour_problem(mesh.tets, mesh.neighbours), "");
  EXPECT_EQ(mesh.neighbours, compute_neighbours(mesh.tets));
  const CheckReport report = check_mesh(input, mesh);
  EXPECT_TRUE(report.ok()) << violations(report);
}

TEST(HealSeams, FinishMeshOnGeneratedShapes) {
  for (const char* name : {"sphere", "torus", "genus3", "nested"}) {
    for (int k : {2, 4}) {
      SCOPED_TRACE(std::string(name) + " k=" + std::to_string(k));
      const SurfaceMesh input = generate_surface(name, 1500);
      const Stage s = prepare(input, k);
      ASSERT_GT(s.prepared.split.cut_vertex_count(), 0);
      const MeshResult result = finish_mesh(input, s.prepared, std::vector<PieceTetMesh>(s.results), s.options);
      expect_clean_result(input, s, result);
    }
  }
}

TEST(HealSeams, DirectCallOnWeldedMesh) {
  const SurfaceMesh input = generate_surface("torus", 1500);
  const Stage s = prepare(input, 3);
  TetMesh mesh = weld(s.prepared.split, s.prepared.pieces, std::vector<PieceTetMesh>(s.results));
  const std::size_t tets_before = mesh.tets.size();
  // Tets touching a cut vertex: exactly the cavity.
  std::int64_t touching = 0;
  for (const auto& t : mesh.tets)
    if (std::any_of(t.begin(), t.end(), [&](std::int32_t v) {
          return s.prepared.split.is_cut_vertex(v) &&
                 v < s.prepared.split.input_vertex_count + s.prepared.split.cut_vertex_count();
        }))
      ++touching;
  const SeamStats stats = heal_seams(mesh, input, s.prepared.split, HealOptions{false, 0}, here(s.options));
  EXPECT_EQ(stats.cut_vertices_removed, s.prepared.split.cut_vertex_count());
  EXPECT_EQ(stats.cap_points_removed, 0);
  EXPECT_EQ(stats.tets_in, touching);
  EXPECT_EQ(mesh.tets.size(), tets_before - stats.tets_in + stats.tets_out);
  const CheckReport report = check_mesh(input, mesh);
  EXPECT_TRUE(report.ok()) << violations(report);
  const double volume = enclosed_volume(input);
  EXPECT_NEAR(total_tet_volume(mesh.points, mesh.tets), volume, 1e-9 * volume);
}

// Healing gives the same mesh whatever the order of the tets it is given (the band path orders
// them otherwise than the whole welded mesh, and the owners of the pieces will order them
// otherwise again): the same points in the same order, the same tets. With two layers and the
// caps healed, regions grow past the stars and several parts meet.
TEST(HealSeams, TheOrderOfTheTetsChangesNothing) {
  for (const char* name : {"sphere", "genus3", "nested"})
    for (const HealOptions options : {HealOptions{false, 0}, HealOptions{true, 2}}) {
      SCOPED_TRACE(std::string(name) + (options.remove_cap_points ? " caps, 2 layers" : " cut vertices"));
      const SurfaceMesh input = generate_surface(name, 1500);
      const Stage s = prepare(input, 4);
      TetMesh welded = weld(s.prepared.split, s.prepared.pieces, std::vector<PieceTetMesh>(s.results));
      TetMesh other = shuffled(welded, 7);
      heal_seams(welded, input, s.prepared.split, options, here(s.options));
      heal_seams(other, input, s.prepared.split, options, here(s.options));
      EXPECT_EQ(other.points, welded.points);
      EXPECT_EQ(tet_set(other.tets), tet_set(welded.tets));
      EXPECT_EQ(other.neighbours, compute_neighbours(other.tets));
    }
}

// Once the pieces are built, rank 0 keeps only the split triangles with a cut vertex: healing
// reads nothing else of them, so it gives the same mesh (cut vertices only, and caps healed too).
TEST(HealSeams, SeamTrianglesAreAllHealingReads) {
  const SurfaceMesh input = generate_surface("torus", 1500);
  const Stage s = prepare(input, 4);
  for (const bool heal_caps : {false, true}) {
    SCOPED_TRACE(heal_caps ? "caps healed" : "cut vertices only");
    TetMesh whole = weld(s.prepared.split, s.prepared.pieces, std::vector<PieceTetMesh>(s.results));
    TetMesh trimmed = whole;
    SplitSurface seams = s.prepared.split;
    keep_seam_triangles(seams);
    ASSERT_LT(seams.triangles.size(), s.prepared.split.triangles.size() / 2);
    ASSERT_EQ(seams.parent.size(), seams.triangles.size());
    EXPECT_TRUE(seams.piece.empty());
    const HealOptions options{heal_caps, 0};
    const SeamStats a = heal_seams(whole, input, s.prepared.split, options, here(s.options));
    const SeamStats b = heal_seams(trimmed, input, seams, options, here(s.options));
    EXPECT_EQ(a.cut_vertices_removed, b.cut_vertices_removed);
    EXPECT_EQ(a.cap_points_removed, b.cap_points_removed);
    expect_same_tet_mesh(whole, trimmed);
  }
}

// A region TetGen cannot re-mesh grows by a layer of tets and is tried again; the other regions,
// unchanged, are not meshed again (their first meshes are kept), and the mesh ends clean.
TEST(HealSeams, AFailedRegionGrowsAndTheOthersAreKept) {
  const SurfaceMesh input = generate_surface("torus", 1500);
  const Stage s = prepare(input, 4);
  TetMesh mesh = weld(s.prepared.split, s.prepared.pieces, std::vector<PieceTetMesh>(s.results));
  std::vector<std::size_t> batch_sizes;
  std::vector<std::size_t> first_region_triangles;
  const RegionMesher meshes_here = here(s.options);
  const RegionMesher fails_once = [&](const std::vector<PieceSurface>& regions) {
    std::vector<PieceOutcome> outcomes = meshes_here(regions);
    batch_sizes.push_back(regions.size());
    if (batch_sizes.size() == 1) {
      first_region_triangles.push_back(regions.front().triangles.size());
      outcomes.front().failure = Failure(FailureKind::changed_boundary, -1, {}, "refused by the test");
    } else if (batch_sizes.size() == 2) {
      first_region_triangles.push_back(regions.front().triangles.size());
    }
    return outcomes;
  };
  const SeamStats stats = heal_seams(mesh, input, s.prepared.split, HealOptions{false, 0}, fails_once);
  ASSERT_GE(batch_sizes.size(), 2u);
  ASSERT_GT(batch_sizes[0], 1u);  // several regions, of which the first failed
  EXPECT_EQ(batch_sizes[1], 1u);  // only the grown one is meshed again
  EXPECT_GT(first_region_triangles[1], first_region_triangles[0]);
  EXPECT_EQ(stats.cut_vertices_removed, s.prepared.split.cut_vertex_count());
  const CheckReport report = check_mesh(input, mesh);
  EXPECT_TRUE(report.ok()) << violations(report);
}

TEST(HealSeams, HealingRemovesEveryCapPoint) {
  const SurfaceMesh input = generate_surface("sphere", 1500);
  Stage s = prepare(input, 3, 2.0);
  s.options.heal = Heal::on;
  const MeshResult result = finish_mesh(input, s.prepared, std::vector<PieceTetMesh>(s.results), s.options);
  expect_clean_result(input, s, result);
  // Only input vertices and Steiner points TetGen put strictly inside: none on a cut plane.
  const auto& plane = s.prepared.planes;
  const int axis = coordinate_axis_of(plane[0].normal);
  for (std::size_t v = input.points.size(); v < result.mesh.points.size(); ++v)
    for (const auto& p : plane) EXPECT_NE(result.mesh.points[v][axis], p.offset) << "a point on a cut plane";
  // Every re-meshed tet is marked as such.
  std::int64_t remeshed = 0;
  for (auto piece : result.mesh.piece) remeshed += piece == -1;
  EXPECT_EQ(remeshed, result.seam.tets_out);
}

TEST(HealSeams, WithoutHealingCapsKeepTheirInteriorPoints) {
  const SurfaceMesh input = generate_surface("sphere", 1500);
  Stage s = prepare(input, 3, 2.0);
  s.options.heal = Heal::off;
  const auto& split = s.prepared.split;
  const std::size_t cap_points = split.points.size() - split.input_vertex_count - split.cut_vertex_count();
  ASSERT_GT(cap_points, 0u);
  const MeshResult result = finish_mesh(input, s.prepared, std::vector<PieceTetMesh>(s.results), s.options);
  expect_clean_result(input, s, result);
  // Cap interior points are interior to the solid. Those outside the re-meshed region stay, in
  // order, right after the input vertices, with unchanged coordinates; a cap point whose every
  // tet touches a cut vertex lies inside that region and may be replaced by TetGen.
  std::size_t next = input.points.size(), kept = 0;
  for (std::size_t i = 0; i < cap_points; ++i) {
    const auto& p = split.points[split.input_vertex_count + split.cut_vertex_count() + i];
    if (next < result.mesh.points.size() && result.mesh.points[next] == p) {
      ++next;
      ++kept;
    }
  }
  EXPECT_GT(kept, cap_points / 2) << "most cap points lie away from the cut loops";
}

TEST(HealSeams, WithQualityEachCutHealsOnItsOwnWithALayerOfRoom) {
  // With a quality bound the stars grow by two layers; the cuts, far apart, still heal as separate
  // regions (so on separate ranks), and the result is a valid mesh without cap points.
  const SurfaceMesh input = generate_surface("sphere", 4000);
  const Stage s = prepare(input, 3, 1.0, "1.414");
  TetMesh mesh = weld(s.prepared.split, s.prepared.pieces, std::vector<PieceTetMesh>(s.results));
  TetMesh unlayered = mesh;
  const SeamStats layered = heal_seams(mesh, input, s.prepared.split, HealOptions{true, 2}, here(s.options));
  const SeamStats stars = heal_seams(unlayered, input, s.prepared.split, HealOptions{true, 0}, here(s.options));
  EXPECT_GE(layered.regions, 2);
  EXPECT_GT(layered.tets_in, stars.tets_in);
  EXPECT_EQ(layered.cap_points_removed, stars.cap_points_removed);
  const CheckReport report = check_mesh(input, mesh);
  EXPECT_TRUE(report.ok()) << violations(report);
  const double volume = enclosed_volume(input);
  EXPECT_NEAR(total_tet_volume(mesh.points, mesh.tets), volume, 1e-9 * volume);
}

TEST(HealSeams, ThinPiecesHealInTurnsAndEveryPointGoes) {
  // Eight pieces of a small unrefined sphere are thin: the stars of neighbouring cuts meet, so
  // they heal in turns (each round planned on the mesh the previous one left), never as one part.
  const SurfaceMesh input = generate_surface("sphere", 1500);
  Stage s = prepare(input, 8, 1.0);
  s.options.heal = Heal::on;
  TetMesh mesh = weld(s.prepared.split, s.prepared.pieces, std::vector<PieceTetMesh>(s.results));
  int rounds = 0;
  std::size_t regions_meshed = 0;
  const RegionMesher counting = [&](const std::vector<PieceSurface>& regions) {
    ++rounds;
    regions_meshed += regions.size();
    return here(s.options)(regions);
  };
  const SeamStats stats = heal_seams(mesh, input, s.prepared.split, HealOptions{true, 0}, counting);
  EXPECT_GE(rounds, 2);
  EXPECT_EQ(stats.cut_vertices_removed, s.prepared.split.cut_vertex_count());
  EXPECT_EQ(stats.cap_points_removed, static_cast<std::int64_t>(s.prepared.split.cap_point_plane.size()));
  // Every cut heals as a region of its own (or more), never merged with its neighbours.
  EXPECT_GE(regions_meshed, s.prepared.planes.size());
  EXPECT_GE(stats.regions, static_cast<std::int64_t>(s.prepared.planes.size()));
  const CheckReport report = check_mesh(input, mesh);
  EXPECT_TRUE(report.ok()) << violations(report);
  const double volume = enclosed_volume(input);
  EXPECT_NEAR(total_tet_volume(mesh.points, mesh.tets), volume, 1e-9 * volume);
}

// A chain of cuts heals the same alone as beside the others (seam_chains.hpp): healing the chains
// one at a time, each cut out of the whole welded mesh (seam_chain_band.hpp), gives the mesh
// healing them all at once gives, the same points in the same order and the same tets, so a chain
// can be healed wherever its tets are. With a quality bound the regions add points, and two
// layers of room make the bands deeper.
TEST(HealSeams, ChainsHealTheSameOneAtATime) {
  int several = 0;
  for (const char* name : {"sphere", "torus", "genus3", "nested"})
    for (int k : {3, 5})
      for (const bool quality : {false, true}) {
        SCOPED_TRACE(std::string(name) + " k=" + std::to_string(k) + (quality ? " quality" : ""));
        const SurfaceMesh input = generate_surface(name, 2000);
        const Stage s = prepare(input, k, 1.0, quality ? "1.414" : "");
        const HealOptions options{quality, quality ? 2 : 0, false};
        const SplitSurface& split = s.prepared.split;
        TetMesh all = weld(split, s.prepared.pieces, std::vector<PieceTetMesh>(s.results));
        TetMesh one_at_a_time = all;
        const SeamStats together = heal_seams(all, input, split, options, here(s.options));
        std::size_t chains = 0;
        ASSERT_NO_FATAL_FAILURE(heal_chain_by_chain(one_at_a_time, input, split, options, here(s.options), chains));
        EXPECT_EQ(together.chains, static_cast<std::int64_t>(chains));
        several += chains > 1;
        EXPECT_EQ(one_at_a_time.points, all.points);
        EXPECT_EQ(tet_set(one_at_a_time.tets), tet_set(all.tets));
        EXPECT_EQ(one_at_a_time.neighbours, compute_neighbours(one_at_a_time.tets));
        drop_unused_points(one_at_a_time);  // (the chains' vertices; kept to compare the numbering)
        const CheckReport report = check_mesh(input, one_at_a_time);
        EXPECT_TRUE(report.ok()) << violations(report);
      }
  EXPECT_GE(several, 8);  // 10 of the 16: most cuts of a partition heal apart
}

// The cuts of thin pieces meet: their seams form one chain, which plans its rounds as a whole.
TEST(HealSeams, CutsOfThinPiecesAreOneChain) {
  const SurfaceMesh input = generate_surface("sphere", 1500);
  const Stage thin = prepare(input, 8);
  TetMesh mesh = weld(thin.prepared.split, thin.prepared.pieces, std::vector<PieceTetMesh>(thin.results));
  const SeamStats stats = heal_seams(mesh, input, thin.prepared.split, HealOptions{true, 0}, here(thin.options));
  EXPECT_LT(stats.chains, static_cast<std::int64_t>(thin.prepared.planes.size()));
  EXPECT_GE(stats.chains, 1);
  // Wider pieces: without a quality bound, the tets inside span a piece from cap to cap, so the
  // caps' points (--heal) chain the cuts; the cut vertices on the surface do not.
  const SurfaceMesh finer = generate_surface("sphere", 6000);
  const Stage wide = prepare(finer, 3);
  mesh = weld(wide.prepared.split, wide.prepared.pieces, std::vector<PieceTetMesh>(wide.results));
  EXPECT_EQ(seam_chain_planes(mesh, wide.prepared.split, HealOptions{false, 0}).size(), 2u);
  EXPECT_EQ(seam_chain_planes(mesh, wide.prepared.split, HealOptions{true, 0}).size(), 1u);
}

TEST(HealSeams, OnePieceChangesNothing) {
  const SurfaceMesh input = generate_surface("sphere", 800);
  const Stage s = prepare(input, 1);
  TetMesh mesh = weld(s.prepared.split, s.prepared.pieces, std::vector<PieceTetMesh>(s.results));
  const TetMesh before = mesh;
  const SeamStats stats = heal_seams(mesh, input, s.prepared.split, HealOptions{true, 0}, here(s.options));
  EXPECT_EQ(stats.cut_vertices_removed, 0);
  EXPECT_EQ(stats.tets_in, 0);
  EXPECT_EQ(stats.tets_out, 0);
  EXPECT_EQ(mesh.points, before.points);
  EXPECT_EQ(mesh.tets, before.tets);
  EXPECT_EQ(mesh.neighbours, before.neighbours);
}

TEST(HealSeams, UnusedInputVerticesAreDropped) {
  // Unused input points (first, in the middle and last) are not in the output, the others keep
  // their order, and boundary_faces is the input in output numbering.
  const SurfaceMesh sphere = generate_surface("sphere", 1000);
  SurfaceMesh input;
  input.points.push_back({5, 5, 5});
  for (std::size_t i = 0; i < sphere.points.size(); ++i) {
    input.points.push_back(sphere.points[i]);
    if (i == sphere.points.size() / 2) input.points.push_back({0.01, 0.02, 0.03});  // inside, unused
  }
  input.points.push_back({-7, 0, 0});
  std::vector<std::int32_t> id(sphere.points.size());
  for (std::size_t i = 0; i < sphere.points.size(); ++i)
    id[i] = static_cast<std::int32_t>(i + 1 + (i > sphere.points.size() / 2 ? 1 : 0));
  for (const auto& t : sphere.triangles) input.triangles.push_back({id[t[0]], id[t[1]], id[t[2]]});

  const Stage s = prepare(input, 3);
  const MeshResult result = finish_mesh(input, s.prepared, std::vector<PieceTetMesh>(s.results), s.options);
  for (std::size_t v = 0; v < sphere.points.size(); ++v) ASSERT_EQ(result.mesh.points[v], sphere.points[v]);
  EXPECT_EQ(result.boundary_faces, sphere.triangles);  // renumbered: stored
  EXPECT_EQ(result.seam.cut_vertices_removed, s.prepared.split.cut_vertex_count());
  for (const auto& p : result.mesh.points) {
    EXPECT_NE(p, (Point3{5, 5, 5}));
    EXPECT_NE(p, (Point3{0.01, 0.02, 0.03}));
    EXPECT_NE(p, (Point3{-7, 0, 0}));
  }
  const CheckReport report = check_mesh(sphere, result.mesh);
  EXPECT_TRUE(report.ok()) << violations(report);
}

}  // namespace
}  // namespace partet
