// One .vtu file written array by array: read back whole across several compression batches, its
// head keeps its length when the offsets are written last, and arrays of the wrong size or out
// of order are refused.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "io/mesh_formats.hpp"
#include "io/mesh_sink.hpp"
#include "io/vtu_file.hpp"
#include "io/vtu_read.hpp"
#include "partet/errors.hpp"
#include "test_support.hpp"

namespace partet {
namespace {

std::string empty_file(const std::string& name) {
  const std::string path = test::temp_dir("vtu_file") + "/" + name;
  std::ofstream(path).close();  // the writer writes into a file that exists (an OutputSet's temporary)
  return path;
}

TEST(VtuFile, ManyBatchesReadBackWhole) {
  // 600k tets: their connectivity alone (19 MB) is more than one batch of blocks.
  std::mt19937 random(3);
  TetMesh mesh;
  for (int i = 0; i < 100000; ++i)
    mesh.points.push_back({std::ldexp(random(), -20), std::ldexp(random(), -21), std::ldexp(random(), -22)});
  std::uniform_int_distribution<std::int32_t> id(0, 99999);
  for (int t = 0; t < 600000; ++t) {
    mesh.tets.push_back({id(random), id(random), id(random), id(random)});
    mesh.piece.push_back(t % 5);
  }
  const std::vector<Triangle> boundary;
  const std::string path = empty_file("many.vtu");
  write_vtu(vtu_rows({mesh, boundary}), path, "many.vtu");
  MeshPart read;
  read_vtu_file(path, read, false);
  ASSERT_EQ(read.nodes.size(), mesh.points.size());
  ASSERT_EQ(read.tets.size(), mesh.tets.size());
  for (std::size_t i = 0; i < mesh.points.size(); ++i) ASSERT_EQ(read.nodes[i], mesh.points[i]) << i;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    for (int j = 0; j < 4; ++j) ASSERT_EQ(read.tets[t][j], mesh.tets[t][j]) << t;
}

TEST(VtuFile, RefusesArraysOfTheWrongSizeOrOutOfOrder) {
  const std::string path = empty_file("wrong.vtu");
  VtuFileWriter file(path, "wrong.vtu", 2, 1, false);
  const double xyz[6] = {0, 0, 0, 1, 1, 1};
  EXPECT_THROW(file.array(VtuArray::connectivity, [](ByteSink&) {}), InternalError);  // Points come first
  EXPECT_THROW(file.array(VtuArray::points, [&](ByteSink& out) { out.bytes(xyz, 5 * sizeof(double)); }), OutputError);
}

TEST(VtuFile, EmptyArraysHaveNoBlocks) {
  const TetMesh mesh;
  const std::vector<Triangle> boundary;
  const std::string path = empty_file("empty.vtu");
  write_vtu(vtu_rows({mesh, boundary}), path, "empty.vtu");
  MeshPart read;
  read_vtu_file(path, read, false);
  EXPECT_TRUE(read.nodes.empty());
  EXPECT_TRUE(read.tets.empty());
}

}  // namespace
}  // namespace partet
