#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "partet/errors.hpp"
#include "stages/generate.hpp"
#include "stages/validate.hpp"
#include "stage_batches.hpp"

namespace partet {
namespace {

constexpr double kPi = 3.14159265358979323846;

long long used_vertex_count(const SurfaceMesh& s) {
  std::set<std::int32_t> used;
  for (const Triangle& t : s.triangles) used.insert(t.begin(), t.end());
  return static_cast<long long>(used.size());
}

// V - E + F, with E = 3F / 2 for a closed surface.
long long euler_characteristic(const SurfaceMesh& s) {
  const auto faces = static_cast<long long>(s.triangles.size());
  return used_vertex_count(s) - 3 * faces / 2 + faces;
}

int component_count(const SurfaceMesh& s) {
  std::vector<std::int32_t> parent(s.points.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](std::int32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (const Triangle& t : s.triangles) {
    parent[find(t[1])] = find(t[0]);
    parent[find(t[2])] = find(t[0]);
  }
  std::set<std::int32_t> roots;
  for (const Triangle& t : s.triangles) roots.insert(find(t[0]));
  return static_cast<int>(roots.size());
}

TEST(Generate, ShapeNames) {
  EXPECT_EQ(generated_shape_names(), (std::vector<std::string>{"sphere", "torus", "genus3", "nested", "two_spheres"}));
}

class EveryShape : public ::testing::TestWithParam<std::pair<std::string, int>> {};

TEST_P(EveryShape, IsValidAndNearTheTarget) {
  const auto& [shape, faces] = GetParam();
  SurfaceMesh surface = generate_surface(shape, faces);
  EXPECT_NO_THROW(validate_surface(surface));
  const auto count = static_cast<double>(surface.triangles.size());
  EXPECT_GE(count, 20);
  if (faces >= 100) {
    EXPECT_LE(count, 2.0 * faces);
    EXPECT_GE(count, 0.5 * faces);
  }
  EXPECT_EQ(used_vertex_count(surface), static_cast<long long>(surface.points.size())) << "no unreferenced vertices";
}

std::vector<std::pair<std::string, int>> every_shape_and_size() {
  std::vector<std::pair<std::string, int>> cases;
  for (const std::string& shape : generated_shape_names())
    for (int faces : {1, 7, 100, 1000, 20000}) cases.emplace_back(shape, faces);
  return cases;
}

INSTANTIATE_TEST_SUITE_P(Generate, EveryShape, ::testing::ValuesIn(every_shape_and_size()),
                         [](const auto& info) { return info.param.first + "_" + std::to_string(info.param.second); });

TEST(Generate, Topology) {
  for (int faces : {1, 1000, 20000}) {
    SCOPED_TRACE(faces);
    SurfaceMesh sphere = generate_surface("sphere", faces);
    EXPECT_EQ(euler_characteristic(sphere), 2);
    EXPECT_EQ(component_count(sphere), 1);
    SurfaceMesh torus = generate_surface("torus", faces);
    EXPECT_EQ(euler_characteristic(torus), 0);
    EXPECT_EQ(component_count(torus), 1);
    SurfaceMesh genus3 = generate_surface("genus3", faces);
    EXPECT_EQ(euler_characteristic(genus3), -4);
    EXPECT_EQ(component_count(genus3), 1);
    SurfaceMesh nested = generate_surface("nested", faces);
    EXPECT_EQ(euler_characteristic(nested), 6);
    EXPECT_EQ(component_count(nested), 3);
    SurfaceMesh two = generate_surface("two_spheres", faces);
    EXPECT_EQ(euler_characteristic(two), 4);
    EXPECT_EQ(component_count(two), 2);
  }
}

TEST(Generate, Volumes) {
  const double ball = 4.0 / 3.0 * kPi;
  // Inscribed polyhedra fall short of the smooth volume by O(1/faces).
  EXPECT_NEAR(enclosed_volume(generate_surface("sphere", 20000)), ball, 0.005 * ball);
  EXPECT_LT(enclosed_volume(generate_surface("sphere", 20000)), ball);
  const double nested = ball * (1 - 0.6 * 0.6 * 0.6 + 0.3 * 0.3 * 0.3);
  EXPECT_NEAR(enclosed_volume(generate_surface("nested", 20000)), nested, 0.01 * nested);
  EXPECT_NEAR(enclosed_volume(generate_surface("nested", 1000)), nested, 0.1 * nested);
  EXPECT_NEAR(enclosed_volume(generate_surface("two_spheres", 20000)), 2 * ball, 0.01 * ball);
  const double torus = 2 * kPi * kPi * 1.0 * 0.4 * 0.4;
  EXPECT_NEAR(enclosed_volume(generate_surface("torus", 20000)), torus, 0.01 * torus);
  // 18 of 21 blocks, each 0.25 x 0.25, 0.125 thick.
  EXPECT_NEAR(enclosed_volume(generate_surface("genus3", 5000)), 18 * 0.25 * 0.25 * 0.125, 1e-12);
}

TEST(Generate, IsDeterministic) {
  for (const std::string& shape : generated_shape_names()) {
    SurfaceMesh a = generate_surface(shape, 3000), b = generate_surface(shape, 3000);
    EXPECT_EQ(a.points, b.points) << shape;
    EXPECT_EQ(a.triangles, b.triangles) << shape;
  }
}

TEST(Generate, NoAxisAlignedCoordinates) {
  // The whole shape is turned, so no two vertices share an x coordinate merely by symmetry.
  for (const std::string& shape : generated_shape_names()) {
    SurfaceMesh surface = generate_surface(shape, 2000);
    std::set<double> xs;
    for (const Point3& p : surface.points) xs.insert(p[0]);
    EXPECT_GT(xs.size(), surface.points.size() * 9 / 10) << shape;
  }
}

TEST(Generate, UnknownShapeAndBadCount) {
  try {
    generate_surface("cube", 100);
    FAIL() << "no OptionError";
  } catch (const OptionError& e) {
    EXPECT_STREQ(e.what(), "unknown shape 'cube' (known: sphere, torus, genus3, nested, two_spheres)");
  }
  EXPECT_THROW(generate_surface("sphere", 0), OptionError);
}

// The thin-wall parts: closed, valid, one solid of the volume the profile and the extrusion give.
TEST(GenerateThinWalls, EveryKindIsAValidSolidOfTheExpectedVolume) {
  // Profile (spine height, wall height, extrusion depth) of each kind, as documented.
  const struct {
    const char* kind;
    double base, height, depth;
  } kinds[] = {{"fins", 3, 20, 40}, {"comb", 2, 40, 4}, {"slots", 10, 8, 30}, {"plates", 3, 30, 30}};
  ASSERT_EQ(thin_wall_kinds().size(), std::size(kinds));
  for (const auto& k : kinds)
    for (const auto& [wall, gap] : {std::pair{1.0, 1.0}, {0.5, 2.0}, {2.0, 1.0}})
      for (double turn : {0.0, 30.0}) {
        SCOPED_TRACE(std::string(k.kind) + " wall " + std::to_string(wall) + " gap " + std::to_string(gap) +
                     " turn " + std::to_string(turn));
        ThinWallPart part{k.kind, 7, wall, gap, turn};
        const SurfaceMesh s = generate_thin_walls(part);
        EXPECT_NO_THROW(validate_surface(s));
        EXPECT_EQ(euler_characteristic(s), 2);
        EXPECT_EQ(component_count(s), 1);
        const double width = 2 * gap + 7 * wall + 6 * gap;
        const double volume = (width * k.base + 7 * wall * k.height) * k.depth;
        EXPECT_NEAR(enclosed_volume(s), volume, 1e-9 * volume);
        // CAD-like: vertices only at the corners of the profile, twice (front and back).
        EXPECT_EQ(s.points.size(), 2u * (4 + 4 * 7));
      }
}

TEST(GenerateThinWalls, AxisAlignedUnlessTurned) {
  const SurfaceMesh straight = generate_thin_walls(ThinWallPart{"fins", 5, 1, 1, 0});
  std::set<double> xs;
  for (const Point3& p : straight.points) xs.insert(p[0]);
  EXPECT_EQ(xs.size(), 2u + 2 * 5);  // the two ends and both sides of each fin: walls share their planes
}

TEST(GenerateThinWalls, BadPartsAreRefused) {
  EXPECT_THROW(generate_thin_walls(ThinWallPart{"gear"}), OptionError);
  EXPECT_THROW(generate_thin_walls(ThinWallPart{"fins", 0}), OptionError);
  EXPECT_THROW(generate_thin_walls(ThinWallPart{"fins", 3, 0, 1}), OptionError);
  EXPECT_THROW(generate_thin_walls(ThinWallPart{"fins", 3, 1, std::nan("")}), OptionError);
}

}  // namespace
}  // namespace partet
