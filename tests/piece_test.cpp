// Piece assembly: assemble_pieces numbers each slab's closed surface locally, and
// check_piece_topology rejects pieces that are not closed, manifold and oriented.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "stages/closure.hpp"
#include "partet/errors.hpp"
#include "stages/generate.hpp"
#include "stages/partition.hpp"
#include "stages/piece.hpp"
#include "stages/validate.hpp"
#include "stage_helpers.hpp"
#include "stage_batches.hpp"

namespace partet {
namespace {

using namespace partet::test;

struct Assembled {
  SurfaceMesh input;
  std::vector<CutPlane> planes;
  SplitSurface split;
  std::vector<Cap> caps;
  std::vector<PieceSurface> pieces;
};

Assembled assemble(const SurfaceMesh& input, int k, double density) {
  Assembled a;
  a.input = input;
  a.planes = choose_cut_planes(input, k);
  a.split = split_at_planes(input, a.planes);
  a.caps = build_caps(a.split, a.planes, density);
  a.pieces = assemble_pieces(a.split, a.caps);
  return a;
}

std::vector<Triangle> global_triangles(const PieceSurface& piece) {
  std::vector<Triangle> out;
  for (const auto& t : piece.triangles)
    out.push_back({piece.global_ids[t[0]], piece.global_ids[t[1]], piece.global_ids[t[2]]});
  return out;
}

void expect_consistent_pieces(const Assembled& a) {
  const int k = static_cast<int>(a.planes.size()) + 1;
  ASSERT_EQ(a.pieces.size(), static_cast<std::size_t>(k));
  std::vector<Triangle> expected_split;  // what split_at_planes produced
  for (int p = 0; p < k; ++p) {
    SCOPED_TRACE("piece " + std::to_string(p));
    const PieceSurface& piece = a.pieces[p];
    EXPECT_EQ(piece.index, p);
    ASSERT_EQ(piece.points.size(), piece.global_ids.size());
    // Global ids strictly ascending, valid, and the points are the global points.
    for (std::size_t i = 0; i < piece.global_ids.size(); ++i) {
      if (i > 0) EXPECT_LT(piece.global_ids[i - 1], piece.global_ids[i]);
      ASSERT_GE(piece.global_ids[i], 0);
      ASSERT_LT(piece.global_ids[i], static_cast<std::int32_t>(a.split.points.size()));
      EXPECT_EQ(piece.points[i], a.split.points[piece.global_ids[i]]);
    }
    // Every local point is used, every local id is in range.
    std::vector<char> used(piece.points.size(), 0);
    for (const auto& t : piece.triangles)
      for (auto v : t) {
        ASSERT_GE(v, 0);
        ASSERT_LT(v, static_cast<std::int32_t>(piece.points.size()));
        used[v] = 1;
      }
    EXPECT_EQ(std::count(used.begin(), used.end(), 0), 0) << "unused local points";

    // Input vertices of the piece are exactly those in its slab.
    for (auto g : piece.global_ids)
      if (!a.split.is_cut_vertex(g) && g < a.split.input_vertex_count)
        EXPECT_EQ(piece_of_point(a.planes, a.split.points[g]), p);

    // Split triangles of this piece + caps below (as is) and above (reversed).
    std::vector<Triangle> expected;
    for (std::size_t t = 0; t < a.split.triangles.size(); ++t)
      if (a.split.piece[t] == p) {
        expected.push_back(a.split.triangles[t]);
        expected_split.push_back(a.split.triangles[t]);
      }
    for (const Cap& cap : a.caps) {
      if (cap.plane == p) {
        expected.insert(expected.end(), cap.triangles.begin(), cap.triangles.end());
      }
      if (cap.plane + 1 == p)
        for (const auto& t : cap.triangles) expected.push_back({t[0], t[2], t[1]});
    }
    const auto global = global_triangles(piece);
    EXPECT_EQ(canonical_set(global), canonical_set(expected));

    EXPECT_NO_THROW(check_piece_topology(piece));
    EXPECT_EQ(closed_oriented_problem(piece.triangles), "");
    // A closed, outward piece encloses a positive volume.
    EXPECT_GT(enclosed_volume(SurfaceMesh{piece.points, piece.triangles}), 0);
  }
  // Each split triangle is in exactly one piece.
  EXPECT_EQ(canonical_set(expected_split).size(), a.split.triangles.size());
}

TEST(AssemblePieces, IdsAndTrianglesConsistent) {
  for (const char* name : {"sphere", "torus", "genus3", "nested"}) {
    for (int k : {1, 2, 5}) {
      for (double density : {0.0, 1.0}) {
        SCOPED_TRACE(std::string(name) + " k=" + std::to_string(k) + " density=" + std::to_string(density));
        expect_consistent_pieces(assemble(generate_surface(name, 2000), k, density));
      }
    }
  }
}

TEST(AssemblePieces, SinglePieceIsTheInput) {
  const SurfaceMesh s = generate_surface("torus", 800);
  const Assembled a = assemble(s, 1, 1.0);
  ASSERT_EQ(a.pieces.size(), 1u);
  EXPECT_EQ(a.pieces[0].points, s.points);  // all input points are used
  EXPECT_EQ(a.pieces[0].triangles, s.triangles);
}

TEST(AssemblePieces, VolumesAddUpToTheInput) {
  // The caps cancel between neighbouring pieces: the pieces' volumes sum to the input's.
  for (const char* name : {"sphere", "torus", "nested", "two_spheres"}) {
    SCOPED_TRACE(name);
    const SurfaceMesh s = generate_surface(name, 2000);
    const Assembled a = assemble(s, name == std::string("two_spheres") ? 3 : 4, 1.0);
    double sum = 0;
    for (const auto& piece : a.pieces) sum += enclosed_volume(SurfaceMesh{piece.points, piece.triangles});
    const double total = enclosed_volume(s);
    EXPECT_NEAR(sum, total, 1e-12 * total);
  }
}

TEST(AssemblePieces, PiecesAreFreeOfSelfIntersections) {
  for (const char* name : {"torus", "nested", "genus3"}) {
    SCOPED_TRACE(name);
    const Assembled a = assemble(generate_surface(name, 1500), 3, 1.0);
    for (const auto& piece : a.pieces)
      EXPECT_NO_THROW(check_no_self_intersections(SurfaceMesh{piece.points, piece.triangles}, "piece"));
  }
}

// A closed octahedron as a piece.
PieceSurface octahedron() {
  PieceSurface p;
  p.index = 7;
  p.points = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  p.global_ids = {0, 1, 2, 3, 4, 5};
  p.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  return p;
}

TEST(CheckPieceTopology, AcceptsAClosedPiece) {
  const PieceSurface p = octahedron();
  EXPECT_GT(enclosed_volume(SurfaceMesh{p.points, p.triangles}), 0);
  EXPECT_NO_THROW(check_piece_topology(p));
}

TEST(CheckPieceTopology, RejectsOpenPiece) {
  PieceSurface p = octahedron();
  p.triangles.pop_back();
  try {
    check_piece_topology(p);
    FAIL() << "open piece accepted";
  } catch (const MeshingError& e) {
    EXPECT_EQ(e.failure.kind, FailureKind::bad_surface);
    EXPECT_EQ(e.failure.piece, 7);
    EXPECT_NE(std::string(e.what()).find("piece 7"), std::string::npos) << e.what();
  }
}

TEST(CheckPieceTopology, RejectsFlippedTriangle) {
  PieceSurface p = octahedron();
  std::swap(p.triangles[3][1], p.triangles[3][2]);
  EXPECT_THROW(check_piece_topology(p), MeshingError);
}

TEST(CheckPieceTopology, RejectsDegenerateTriangle) {
  PieceSurface p = octahedron();
  p.triangles.push_back({0, 0, 1});
  EXPECT_THROW(check_piece_topology(p), MeshingError);
}

TEST(CheckPieceTopology, RejectsDuplicatedTriangle) {
  PieceSurface p = octahedron();
  p.triangles.push_back(p.triangles[0]);
  p.triangles.push_back({p.triangles[0][0], p.triangles[0][2], p.triangles[0][1]});
  EXPECT_THROW(check_piece_topology(p), MeshingError);
}

}  // namespace
}  // namespace partet
