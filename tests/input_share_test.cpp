// The input's checks split into shares (as the ranks of an MPI job run them) give the verdict of
// the whole input's check: the same first problem, the same counts, the same volume.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "job/job.hpp"
#include "partet/errors.hpp"
#include "stages/generate.hpp"
#include "stages/input_share.hpp"
#include "stages/validate.hpp"
#include "test_support.hpp"

namespace partet {
namespace {

using test::input_error;

// The shares of `surface` as the checking ranks build them, the input streamed in parts of
// `part` values (as the MPI layer sends it).
std::vector<InputShare> shares_of(const SurfaceMesh& surface, int shares, std::size_t part) {
  const std::vector<std::uint16_t> owner = vertex_shares(surface.points, shares);
  const std::size_t vertices = surface.points.size(), faces = surface.triangles.size();
  std::vector<InputShare> result;
  for (int s = 0; s < shares; ++s) {
    InputShareBuilder builder(s, shares, vertices, faces);
    for (std::size_t i = 0; i < vertices; i += part) builder.add_vertex_shares(&owner[i], std::min(part, vertices - i));
    for (std::size_t i = 0; i < faces; i += part) builder.add_faces(&surface.triangles[i], std::min(part, faces - i));
    for (std::size_t i = 0; i < vertices; i += part) builder.add_points(&surface.points[i], std::min(part, vertices - i));
    result.push_back(builder.finish());
  }
  return result;
}

InputFindings merged_findings(const std::vector<InputShare>& shares) {
  InputFindings merged;
  for (const InputShare& share : shares) merged.merge(check_share(share));
  return merged;
}

std::string verdict(const InputFindings& findings) { return input_error([&] { judge_input(findings); }); }

void expect_same(const FirstProblem& a, const FirstProblem& b, const std::string& kind) {
  EXPECT_EQ(a.count, b.count) << kind;
  EXPECT_EQ(a.order, b.order) << kind;
  for (int i = 0; i < 4; ++i) EXPECT_EQ(a.names[i], b.names[i]) << kind << " name " << i;
}

SurfaceMesh tetrahedron(const Point3& origin = {0, 0, 0}) {
  SurfaceMesh tet;
  tet.points = {origin, {origin[0] + 1, origin[1], origin[2]}, {origin[0], origin[1] + 1, origin[2]},
                {origin[0], origin[1], origin[2] + 1}};
  tet.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return tet;
}

// The same surface with its vertices numbered at random: shares by position then hold vertices
// from all over the numbering.
SurfaceMesh shuffled(SurfaceMesh s, unsigned seed) {
  std::vector<std::int32_t> order(s.points.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(seed));
  std::vector<Point3> points(s.points.size());
  for (std::size_t v = 0; v < order.size(); ++v) points[static_cast<std::size_t>(order[v])] = s.points[v];
  for (Triangle& t : s.triangles)
    for (std::int32_t& v : t) v = order[static_cast<std::size_t>(v)];
  s.points = points;
  return s;
}

// Valid and broken surfaces, each broken one in a way the checks name.
std::vector<std::pair<std::string, SurfaceMesh>> cases() {
  std::vector<std::pair<std::string, SurfaceMesh>> all;
  const SurfaceMesh sphere = generate_surface("sphere", 5000), genus3 = generate_surface("genus3", 4000);
  all.emplace_back("sphere", sphere);
  all.emplace_back("genus3", genus3);
  all.emplace_back("nested", generate_surface("nested", 4000));
  all.emplace_back("two_spheres", generate_surface("two_spheres", 4000));
  all.emplace_back("shuffled genus3", shuffled(genus3, 7));
  SurfaceMesh s = genus3;
  s.triangles.erase(s.triangles.begin() + 1234);
  all.emplace_back("open", s);
  all.emplace_back("open shuffled", shuffled(s, 3));
  s = genus3;
  std::swap(s.triangles[777][1], s.triangles[777][2]);
  std::swap(s.triangles[3001][0], s.triangles[3001][2]);
  all.emplace_back("flipped faces", s);
  all.emplace_back("flipped faces shuffled", shuffled(s, 5));
  s = genus3;
  s.triangles.push_back(s.triangles[10]);
  s.triangles.push_back({s.triangles[10][0], s.triangles[10][2], s.triangles[10][1]});
  all.emplace_back("crowded edges", s);
  s = sphere;
  for (Triangle& t : s.triangles) std::swap(t[1], t[2]);
  all.emplace_back("inside out", s);
  s = sphere;
  s.triangles[50] = {s.triangles[50][0], s.triangles[50][1], s.triangles[50][0]};
  all.emplace_back("repeated vertex", s);
  s = tetrahedron();
  s.points[3] = {0.5, 0.5, 0};
  all.emplace_back("collinear corners", s);
  s = sphere;  // vertex 10 stored twice: the faces of half its fan use the copy
  s.points.push_back(s.points[10]);
  for (std::size_t f = 0, changed = 0; f < s.triangles.size() && changed < 2; ++f)
    for (std::int32_t& v : s.triangles[f])
      if (v == 10) v = static_cast<std::int32_t>(s.points.size() - 1), ++changed;
  all.emplace_back("duplicate vertex", s);
  s = tetrahedron();  // two tetrahedra touching at vertex 0
  s.points.insert(s.points.end(), {{-1, 0, 0}, {0, -1, 0}, {0, 0, -1}});
  s.triangles.insert(s.triangles.end(), {{0, 4, 5}, {0, 6, 4}, {0, 5, 6}, {4, 6, 5}});
  all.emplace_back("split fans", s);
  s = sphere;
  s.points.push_back({1e12, 1e12, 1e12});
  all.emplace_back("far unused vertex", s);
  return all;
}

TEST(InputShare, SharesGiveTheWholeInputsVerdict) {
  for (const auto& [name, surface] : cases()) {
    const InputFindings whole = check_whole(surface);
    const std::string expected = verdict(whole);
    for (int shares : {1, 2, 3, 5, 8})
      for (std::size_t part : {std::size_t(7), std::size_t(100000)}) {
        SCOPED_TRACE(name + ", " + std::to_string(shares) + " shares, parts of " + std::to_string(part));
        const InputFindings merged = merged_findings(shares_of(surface, shares, part));
        EXPECT_EQ(verdict(merged), expected);
        expect_same(merged.repeated, whole.repeated, "repeated");
        expect_same(merged.collinear, whole.collinear, "collinear");
        expect_same(merged.duplicate, whole.duplicate, "duplicate");
        EXPECT_EQ(merged.duplicate_at, whole.duplicate_at);
        // Edges are looked at only without faces repeating a vertex, in the share that holds one
        // and in the whole input; other shares may count edges the verdict does not name.
        if (whole.repeated.count == 0) {
          expect_same(merged.border, whole.border, "border");
          expect_same(merged.crowded, whole.crowded, "crowded");
          expect_same(merged.misoriented, whole.misoriented, "misoriented");
          expect_same(merged.split, whole.split, "split");
        }
        const long double tolerance = 1e-12L * (1 + std::abs(whole.six_volume));
        EXPECT_NEAR(static_cast<double>(merged.six_volume), static_cast<double>(whole.six_volume),
                    static_cast<double>(tolerance));
      }
  }
}

// One process checking the input in shares on threads finds what the whole check finds.
TEST(InputShare, SharesOnThreadsGiveTheWholeInputsFindings) {
  for (const auto& [name, surface] : cases()) {
    const InputFindings whole = check_whole(surface);
    for (int shares : {2, 3}) {
      SCOPED_TRACE(name + ", " + std::to_string(shares) + " shares on threads");
      const InputFindings threaded = check_whole(surface, shares);
      EXPECT_EQ(verdict(threaded), verdict(whole));
      expect_same(threaded.duplicate, whole.duplicate, "duplicate");
      if (whole.repeated.count == 0) expect_same(threaded.border, whole.border, "border");
    }
  }
}

TEST(InputShare, TheVerdictNamesTheProblemAsTheWholeCheckDoes) {
  for (const auto& [name, surface] : cases()) {
    const std::string message = verdict(merged_findings(shares_of(surface, 3, 1000)));
    if (name == "sphere" || name == "genus3" || name == "nested" || name == "two_spheres" || name == "shuffled genus3" ||
        name == "far unused vertex")
      EXPECT_EQ(message, "(no InputError thrown)") << name;
    else
      EXPECT_EQ(message, input_error([&] { check_input(surface); })) << name;
  }
  EXPECT_TRUE(test::contains(verdict(merged_findings(shares_of(cases()[5].second, 4, 50))), "input is not closed: 3 border edges"));
}

// What lets each rank hold only its share: a share is a compact part of the surface, so few
// faces are in two shares.
TEST(InputShare, ASharesHoldsAboutItsPart) {
  for (const SurfaceMesh& surface : {generate_surface("sphere", 20000), shuffled(generate_surface("genus3", 20000), 11)}) {
    const std::vector<InputShare> shares = shares_of(surface, 4, 4096);
    std::size_t owned = 0;
    for (const InputShare& share : shares) {
      EXPECT_LT(share.faces.size(), surface.triangles.size() * 3 / 10);
      EXPECT_LT(share.points.size(), surface.points.size() * 3 / 10);
      owned += static_cast<std::size_t>(std::count(share.numbering.owned.begin(), share.numbering.owned.end(), 1));
    }
    EXPECT_EQ(owned, surface.points.size()) << "every vertex has one share";
  }
}

TEST(InputShare, AShareMissingPartsOfTheInputIsAnError) {
  const SurfaceMesh sphere = generate_surface("sphere", 1000);
  const std::vector<std::uint16_t> owner = vertex_shares(sphere.points, 2);
  InputShareBuilder builder(0, 2, sphere.points.size(), sphere.triangles.size());
  builder.add_vertex_shares(owner.data(), owner.size());
  builder.add_faces(sphere.triangles.data(), sphere.triangles.size() - 1);
  builder.add_points(sphere.points.data(), sphere.points.size());
  EXPECT_THROW(builder.finish(), Error);
}

TEST(InputShare, VerticesAtOnePositionShareAShare) {
  std::vector<Point3> points = generate_surface("sphere", 2000).points;
  points.push_back(points[17]);
  points.push_back({-0.0, points[3][1], points[3][2]});
  points[3][0] = 0.0;
  for (int shares : {2, 3, 7}) {
    const std::vector<std::uint16_t> owner = vertex_shares(points, shares);
    EXPECT_EQ(owner[17], owner[points.size() - 2]);
    EXPECT_EQ(owner[3], owner[points.size() - 1]);
    EXPECT_EQ(*std::max_element(owner.begin(), owner.end()), shares - 1) << "every share has vertices";
  }
}

}  // namespace
}  // namespace partet
