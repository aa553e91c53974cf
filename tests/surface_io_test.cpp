#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "partet/errors.hpp"
#include "stages/generate.hpp"
#include "io/read_surface.hpp"
#include "io/write_surface.hpp"
#include "stages/validate.hpp"
#include "io/plain_off.hpp"
#include "test_support.hpp"
#include "stage_batches.hpp"

namespace partet {
namespace {

using test::contains;
using test::input_error;

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

const char* const kTetrahedronOff =
    "OFF\n4 4 0\n"
    "0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
    "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

// A unit cube with quad faces, outward oriented.
const char* const kCubeVertices = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n";
const int kCubeQuads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};

class SurfaceIoTest : public ::testing::Test {
 protected:
  std::string dir_ = test::temp_dir("surface_io");
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
};

TEST_F(SurfaceIoTest, RoundTripIsBitIdentical) {
  SurfaceMesh surface = generate_surface("nested", 2000);
  // Values whose shortest decimal form needs all 17 digits, plus signed zero and extremes.
  surface.points.push_back({0.1, 1.0 / 3.0, -0.0});
  surface.points.push_back({1e-300, -1.7976931348623157e308, 2.2250738585072014e-308});
  surface.points.push_back({std::nextafter(1.0, 2.0), -std::nextafter(0.5, 0.0), 123456789.123456789});
  const std::string file = path("round_trip.off");
  write_off(surface, file);
  SurfaceMesh back = read_surface(file);
  ASSERT_EQ(back.points.size(), surface.points.size());
  ASSERT_EQ(back.triangles, surface.triangles);
  for (std::size_t v = 0; v < surface.points.size(); ++v)
    ASSERT_EQ(std::memcmp(back.points[v].data(), surface.points[v].data(), sizeof(Point3)), 0) << "vertex " << v;
  std::ifstream tmp(file + ".tmp");
  EXPECT_FALSE(tmp.good()) << "the temporary file was left behind";
}

TEST_F(SurfaceIoTest, WriteFailsWithOutputError) {
  SurfaceMesh surface = generate_surface("sphere", 20);
  EXPECT_THROW(write_off(surface, path("no_such_dir/out.off")), OutputError);
}

TEST_F(SurfaceIoTest, ReadsTetrahedronOff) {
  write_text(path("tet.off"), kTetrahedronOff);
  SurfaceMesh surface = read_surface(path("tet.off"));
  EXPECT_EQ(surface.points.size(), 4u);
  EXPECT_EQ(surface.triangles.size(), 4u);
  EXPECT_NO_THROW(validate_surface(surface));
}

TEST_F(SurfaceIoTest, QuadsAreTriangulated) {
  std::string off = std::string("OFF\n8 6 0\n") + kCubeVertices;
  for (const auto& q : kCubeQuads)
    off += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) + " " +
           std::to_string(q[3]) + "\n";
  write_text(path("cube.off"), off);
  SurfaceMesh surface = read_surface(path("cube.off"));
  EXPECT_EQ(surface.triangles.size(), 12u);
  EXPECT_NO_THROW(validate_surface(surface));
  EXPECT_DOUBLE_EQ(enclosed_volume(surface), 1.0);
}

// An OFF prism of height 1 over a counterclockwise outline, with one polygon for the top and
// one for the bottom. The top starts at corner `top_start` of the outline.
std::string prism_off(const std::vector<std::array<double, 2>>& outline, std::size_t top_start) {
  const std::size_t k = outline.size();
  std::ostringstream off;
  off.precision(17);
  off << "OFF\n" << 2 * k << " " << k + 2 << " 0\n";
  for (double z : {0.0, 1.0})
    for (const auto& p : outline) off << p[0] << " " << p[1] << " " << z << "\n";
  off << k;
  for (std::size_t i = k; i-- > 0;) off << " " << i;  // bottom, seen from below
  off << "\n" << k;
  for (std::size_t i = 0; i < k; ++i) off << " " << k + (top_start + i) % k;
  off << "\n";
  for (std::size_t i = 0; i < k; ++i) {
    std::size_t j = (i + 1) % k;
    off << "4 " << i << " " << j << " " << j + k << " " << i + k << "\n";
  }
  return off.str();
}

TEST_F(SurfaceIoTest, NonConvexPolygonsAreTriangulated) {
  // An L-shaped prism. The top starts at (2, 0), which does not see the whole polygon, so a fan
  // from there would fold over.
  write_text(path("l_prism.off"), prism_off({{{0, 0}}, {{2, 0}}, {{2, 1}}, {{1, 1}}, {{1, 2}}, {{0, 2}}}, 1));
  SurfaceMesh surface = read_surface(path("l_prism.off"));
  EXPECT_EQ(surface.triangles.size(), 4u + 4u + 12u);
  EXPECT_NO_THROW(validate_surface(surface));
  EXPECT_NEAR(enclosed_volume(surface), 3.0, 1e-12);
}

TEST_F(SurfaceIoTest, LargeNonConvexPolygonIsTriangulatedQuickly) {
  // A star with 1000 corners.
  std::vector<std::array<double, 2>> star;
  for (int i = 0; i < 1000; ++i) {
    double angle = 2 * 3.14159265358979323846 * i / 1000, radius = i % 2 ? 0.5 : 1.0;
    star.push_back({radius * std::cos(angle), radius * std::sin(angle)});
  }
  write_text(path("star.off"), prism_off(star, 0));
  SurfaceMesh surface = read_surface(path("star.off"));
  EXPECT_EQ(surface.triangles.size(), 2u * 998u + 2000u);
  EXPECT_NO_THROW(validate_surface(surface));
}

TEST_F(SurfaceIoTest, PolygonWithStraightCornerGetsNoSliver) {
  // Corner 1 lies on the segment from corner 0 to corner 2.
  write_text(path("pentagon.off"), "OFF\n5 1 0\n0 0 0\n1 0 0\n2 0 0\n2 2 0\n0 2 0\n5 0 1 2 3 4\n");
  SurfaceMesh surface = read_surface(path("pentagon.off"));
  ASSERT_EQ(surface.triangles.size(), 3u);
  for (const Triangle& t : surface.triangles) {
    const Point3 &a = surface.points[t[0]], &b = surface.points[t[1]], &c = surface.points[t[2]];
    double twice_area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    EXPECT_GT(twice_area, 0) << t[0] << " " << t[1] << " " << t[2];
  }
}

TEST_F(SurfaceIoTest, ReadsObjWithQuadsAndSlashes) {
  std::string obj = "# cube\n";
  for (const char* p = kCubeVertices; *p;) {
    const char* end = std::strchr(p, '\n');
    obj += "v " + std::string(p, end) + "\n";
    p = end + 1;
  }
  obj += "vn 0 0 1\n";
  for (const auto& q : kCubeQuads)
    obj += "f " + std::to_string(q[0] + 1) + "//1 " + std::to_string(q[1] + 1) + "//1 " + std::to_string(q[2] + 1) +
           "//1 " + std::to_string(q[3] + 1) + "//1\n";
  write_text(path("cube.obj"), obj);
  SurfaceMesh surface = read_surface(path("cube.obj"));
  EXPECT_EQ(surface.points.size(), 8u);
  EXPECT_EQ(surface.triangles.size(), 12u);
  EXPECT_NO_THROW(validate_surface(surface));
}

TEST_F(SurfaceIoTest, ReadsAsciiPly) {
  std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
      "property double z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
      "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  write_text(path("tet.ply"), ply);
  SurfaceMesh surface = read_surface(path("tet.ply"));
  EXPECT_EQ(surface.points.size(), 4u);
  EXPECT_EQ(surface.triangles, (std::vector<Triangle>{{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}));
  EXPECT_NO_THROW(validate_surface(surface));
}

template <class T>
void append_bytes(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));  // the test machine is little endian, like the formats
  out.append(bytes, sizeof(T));
}

TEST_F(SurfaceIoTest, ReadsBinaryPly) {
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty double x\n"
      "property double y\nproperty double z\nelement face 4\n"
      "property list uchar int vertex_indices\nend_header\n";
  const double points[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1.0 / 3.0}};
  for (const auto& p : points)
    for (double c : p) append_bytes(ply, c);
  const std::int32_t faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (const auto& f : faces) {
    append_bytes<std::uint8_t>(ply, 3);
    for (std::int32_t i : f) append_bytes(ply, i);
  }
  write_text(path("tet_binary.ply"), ply);
  SurfaceMesh surface = read_surface(path("tet_binary.ply"));
  ASSERT_EQ(surface.points.size(), 4u);
  EXPECT_EQ(surface.points[3][2], 1.0 / 3.0);  // doubles arrive unrounded
  EXPECT_NO_THROW(validate_surface(surface));
}

const float kTetPoints[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
const int kTetFaces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};

TEST_F(SurfaceIoTest, ReadsAsciiStlAndMergesCorners) {
  std::string stl = "solid tet\n";
  for (const auto& f : kTetFaces) {
    stl += "  facet normal 0 0 0\n    outer loop\n";
    for (int c : f)
      stl += "      vertex " + std::to_string(kTetPoints[c][0]) + " " + std::to_string(kTetPoints[c][1]) + " " +
             std::to_string(kTetPoints[c][2]) + "\n";
    stl += "    endloop\n  endfacet\n";
  }
  stl += "endsolid tet\n";
  write_text(path("tet.stl"), stl);
  SurfaceMesh surface = read_surface(path("tet.stl"));
  EXPECT_EQ(surface.points.size(), 4u);  // STL repeats corners per facet; they are merged
  EXPECT_EQ(surface.triangles.size(), 4u);
  EXPECT_NO_THROW(validate_surface(surface));
}

TEST_F(SurfaceIoTest, ReadsBinaryStlAndMergesCorners) {
  std::string stl(80, ' ');
  append_bytes<std::uint32_t>(stl, 4);
  for (const auto& f : kTetFaces) {
    for (int i = 0; i < 3; ++i) append_bytes(stl, 0.0f);  // normal
    for (int c : f)
      for (float x : kTetPoints[c]) append_bytes(stl, x);
    append_bytes<std::uint16_t>(stl, 0);
  }
  write_text(path("tet_binary.STL"), stl);  // extensions are case-insensitive
  SurfaceMesh surface = read_surface(path("tet_binary.STL"));
  EXPECT_EQ(surface.points.size(), 4u);
  EXPECT_EQ(surface.triangles.size(), 4u);
  EXPECT_NO_THROW(validate_surface(surface));
}

TEST_F(SurfaceIoTest, MissingFile) {
  std::string message = input_error([&] { read_surface(path("absent.off")); });
  EXPECT_TRUE(contains(message, "cannot open '" + path("absent.off") + "': no such file"));
}

TEST_F(SurfaceIoTest, UnknownExtension) {
  write_text(path("tet.xyz"), kTetrahedronOff);
  std::string message = input_error([&] { read_surface(path("tet.xyz")); });
  EXPECT_TRUE(contains(message, "unknown format '.xyz'"));
  EXPECT_TRUE(contains(message, ".off, .obj, .ply, .stl"));
}

TEST_F(SurfaceIoTest, TruncatedOff) {
  std::string text = kTetrahedronOff;
  write_text(path("cut_in_faces.off"), text.substr(0, text.find("3 0 3 2")));
  EXPECT_TRUE(contains(input_error([&] { read_surface(path("cut_in_faces.off")); }),
                       "the file ends after 2 of 4 faces (truncated?)"));
  write_text(path("cut_in_vertices.off"), text.substr(0, text.find("0 1 0")));
  EXPECT_TRUE(contains(input_error([&] { read_surface(path("cut_in_vertices.off")); }),
                       "the file ends after 2 of 4 vertices (truncated?)"));
}

TEST_F(SurfaceIoTest, GarbageOff) {
  write_text(path("garbage.off"), "this is not a mesh\n");
  EXPECT_TRUE(
      contains(input_error([&] { read_surface(path("garbage.off")); }), "cannot read '" + path("garbage.off") + "'"));
}

TEST_F(SurfaceIoTest, EmptyMesh) {
  write_text(path("empty.off"), "OFF\n0 0 0\n");
  EXPECT_TRUE(contains(input_error([&] { read_surface(path("empty.off")); }), "no faces"));
  write_text(path("points_only.off"), "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n");
  EXPECT_TRUE(contains(input_error([&] { read_surface(path("points_only.off")); }), "no faces"));
  write_text(path("empty.obj"), "# nothing\n");
  EXPECT_TRUE(contains(input_error([&] { read_surface(path("empty.obj")); }), "no faces"));
}

TEST_F(SurfaceIoTest, NanCoordinate) {
  std::string text = kTetrahedronOff;
  text.replace(text.find("0 1 0"), 5, "0 nan 0");
  write_text(path("nan.off"), text);
  EXPECT_TRUE(contains(input_error([&] { read_surface(path("nan.off")); }), "vertex 2 has a non-finite coordinate"));
  text = kTetrahedronOff;
  text.replace(text.find("0 0 1"), 5, "0 0 1e999");
  write_text(path("inf.off"), text);
  EXPECT_TRUE(contains(input_error([&] { read_surface(path("inf.off")); }), "vertex 3 has a non-finite coordinate"));
}

TEST_F(SurfaceIoTest, NanCoordinateInBinaryStl) {
  std::string stl(80, ' ');
  append_bytes<std::uint32_t>(stl, 1);
  for (int i = 0; i < 3; ++i) append_bytes(stl, 0.0f);
  const float corners[3][3] = {{0, 0, 0}, {1, std::numeric_limits<float>::quiet_NaN(), 0}, {0, 1, 0}};
  for (const auto& p : corners)
    for (float x : p) append_bytes(stl, x);
  append_bytes<std::uint16_t>(stl, 0);
  write_text(path("nan.stl"), stl);
  EXPECT_TRUE(contains(input_error([&] { read_surface(path("nan.stl")); }), "has a non-finite coordinate"));
}

TEST_F(SurfaceIoTest, IndexOutOfRange) {
  std::string text = kTetrahedronOff;
  text.replace(text.find("3 0 1 3"), 7, "3 0 1 7");
  write_text(path("bad_index.off"), text);
  EXPECT_TRUE(contains(input_error([&] { read_surface(path("bad_index.off")); }),
                       "face 1 refers to vertex 7, but there are only 4 vertices"));

  // One past the end slips through CGAL's own OBJ check, two past do not; both are named.
  write_text(path("bad_index.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n");
  EXPECT_TRUE(contains(input_error([&] { read_surface(path("bad_index.obj")); }),
                       "face 1 (line 5) refers to vertex 4, but only 3 vertices precede it"));
  write_text(path("bad_index2.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf -4 2 3\n");
  EXPECT_TRUE(contains(input_error([&] { read_surface(path("bad_index2.obj")); }),
                       "face 1 (line 5) refers to vertex -4, but only 3 vertices precede it"));

  write_text(path("bad_index.ply"),
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
             "property double z\nelement face 2\nproperty list uchar int vertex_indices\n"
             "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 7 2\n");
  EXPECT_TRUE(contains(input_error([&] { read_surface(path("bad_index.ply")); }),
                       "face 1 refers to vertex 7, but there are only 3 vertices"));
}

TEST_F(SurfaceIoTest, FaceWithTooFewCorners) {
  write_text(path("two_corners.off"), "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n2 0 1\n");
  EXPECT_TRUE(contains(input_error([&] { read_surface(path("two_corners.off")); }), "face 1 has only 2 corners"));
}

TEST_F(SurfaceIoTest, PolygonThatCannotBeTriangulated) {
  // A bow tie: its two halves wind in opposite directions.
  write_text(path("bowtie.off"), "OFF\n4 1 0\n0 0 0\n1 1 0\n1 0 0\n0 1 0\n4 0 1 2 3\n");
  EXPECT_TRUE(contains(input_error([&] { read_surface(path("bowtie.off")); }),
                       "face 0 has 4 corners and cannot be triangulated"));
  // Repeating a corner is not a polygon either.
  write_text(path("repeat.off"), "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n5 0 1 2 3 1\n");
  EXPECT_TRUE(contains(input_error([&] { read_surface(path("repeat.off")); }),
                       "face 0 has 5 corners and cannot be triangulated"));
}

// The fast plain-OFF path gives exactly what CGAL's general reader gives.
void expect_same_surface(const SurfaceMesh& a, const SurfaceMesh& b) {
  ASSERT_EQ(a.points.size(), b.points.size());
  ASSERT_EQ(a.triangles, b.triangles);
  if (!a.points.empty()) EXPECT_EQ(std::memcmp(a.points.data(), b.points.data(), a.points.size() * sizeof(Point3)), 0);
}

TEST_F(SurfaceIoTest, PlainOffFastPathMatchesTheGeneralReader) {
  SurfaceMesh surface = generate_surface("torus", 3000);
  surface.points.push_back({0.1, 1.0 / 3.0, -0.0});
  surface.points.push_back({1e-300, -1.7976931348623157e308, 2.2250738585072014e-308});
  surface.points.push_back({4.9406564584124654e-324, 123456789.123456789, -1e22});
  const std::string file = path("fast.off");
  write_off(surface, file);
  const auto fast = read_plain_off(file);
  ASSERT_TRUE(fast);
  expect_same_surface(*fast, read_surface_general(file));
  expect_same_surface(*fast, surface);
  // CRLF line ends, comments, blank lines and tabs are still plain.
  write_text(path("crlf.off"), "# comment\r\nOFF\r\n\r\n4 4 0 # counts\r\n0 0 0\r\n1\t0 0\r\n0 1 0\r\n0 0 1\r\n"
                               "3 0 2 1\r\n3 0 1 3\r\n# a comment\r\n3 0 3 2\r\n3 1 2 3\r\n");
  ASSERT_TRUE(read_plain_off(path("crlf.off")));
  expect_same_surface(*read_plain_off(path("crlf.off")), read_surface_general(path("crlf.off")));
}

TEST_F(SurfaceIoTest, PlainOffFastPathDeclinesAnythingElse) {
  const std::vector<std::string> not_plain = {
      "OFF 4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",      // counts on the keyword line
      "COFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",     // another keyword
      "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3 255\n",  // a colour
      "OFF\n4 4 0\n0 0 0\n1 0 0\n0 nan 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",    // non-finite
      "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 7\n",      // index range
      "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n",                               // a quad
      "OFF\n4 4 0\n0 0\n0 1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",      // numbers across lines
      "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\nextra\n",  // trailing content
      "OFF\n4 4 0\n+0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",     // explicit +
      "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n",               // truncated
      "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n3 0 2 1\n0 0 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",      // a vertex late
      "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n",      // a vertex too many
  };
  for (std::size_t i = 0; i < not_plain.size(); ++i) {
    SCOPED_TRACE("case " + std::to_string(i));
    write_text(path("odd.off"), not_plain[i]);
    EXPECT_FALSE(read_plain_off(path("odd.off")));
  }
}

// The fast path reads in blocks of 32 MB that threads parse in runs joined after: a file of
// several blocks comes back exactly, and a vertex after the last triangle is still refused.
TEST_F(SurfaceIoTest, PlainOffFastPathReadsAFileOfManyBlocks) {
  const SurfaceMesh surface = generate_surface("torus", 1'500'000);
  const std::string file = path("blocks.off");
  write_off(surface, file);
  ASSERT_GT(std::filesystem::file_size(file), std::uintmax_t{64} << 20);  // three blocks
  const auto fast = read_plain_off(file);
  ASSERT_TRUE(fast);
  expect_same_surface(*fast, surface);
  {
    std::ofstream(file, std::ios::app) << "0 0 0\n";
  }
  EXPECT_FALSE(read_plain_off(file));
}

TEST_F(SurfaceIoTest, PlainOffFastPathMatchesTheGeneralReaderOnSharedModels) {
  const std::string dir = PARTET_MESHES_DIR;
  if (!std::ifstream(dir + "/spot.off").good()) GTEST_SKIP() << "no shared meshes at " << dir;
  for (const char* name : {"spot", "bob", "fandisk", "adis16480", "nested_blub_3", "two_cubes", "armadillo"}) {
    SCOPED_TRACE(name);
    const std::string file = dir + "/" + name + ".off";
    const auto fast = read_plain_off(file);
    ASSERT_TRUE(fast);
    expect_same_surface(*fast, read_surface_general(file));
  }
}

TEST_F(SurfaceIoTest, ReadsSharedModel) {
  const std::string file = std::string(PARTET_MESHES_DIR) + "/tiny_torus.off";
  if (!std::ifstream(file).good()) GTEST_SKIP() << "no shared meshes at " << PARTET_MESHES_DIR;
  SurfaceMesh surface = read_surface(file);
  EXPECT_EQ(surface.points.size(), 24u);
  EXPECT_EQ(surface.triangles.size(), 48u);
}

}  // namespace
}  // namespace partet
