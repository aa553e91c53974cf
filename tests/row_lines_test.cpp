// The rows of the single-file formats: a string and a file get the same bytes, runs cut anywhere
// join to the whole, the numbers are those of the file's rows, and tets past 2^31 are named in full.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "io/buffered_file.hpp"
#include "io/row_lines.hpp"
#include "stages/spread_mesh.hpp"
#include "test_support.hpp"

namespace partet {
namespace {

constexpr RowLines kAllKinds[] = {RowLines::tetgen_node,  RowLines::tetgen_ele,      RowLines::tetgen_neigh,
                                  RowLines::medit_vertex, RowLines::medit_tet,       RowLines::msh_node,
                                  RowLines::msh_tet,      RowLines::msh_node_binary, RowLines::msh_tet_binary};

struct Rows {
  std::vector<Point3> points;
  std::vector<Tet> tets;
  std::vector<NeighbourRow> neighbours;  // .neigh rows: 64-bit
  std::vector<std::int32_t> region;
};

Rows random_rows(std::size_t n) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-1e3, 1e3);
  std::uniform_int_distribution<std::int32_t> id(-1, 1 << 30);
  std::uniform_int_distribution<std::int64_t> tet(-1, std::int64_t{1} << 40);
  Rows rows;
  for (std::size_t i = 0; i < n; ++i) {
    rows.points.push_back({coordinate(random), coordinate(random), coordinate(random)});
    rows.tets.push_back({id(random), id(random), id(random), id(random)});
    rows.neighbours.push_back({tet(random), tet(random), tet(random), tet(random)});
    rows.region.push_back(1 + static_cast<std::int32_t>(i % 3));
  }
  return rows;
}

// Rows [from, from + n) of `rows` as the kind formats them, row `from` being the file's row `first`.
RowsToFormat run(RowLines lines, const Rows& rows, std::size_t from, std::size_t n, std::int64_t number_from = 0) {
  const void* data = formats_points(lines)               ? static_cast<const void*>(rows.points.data() + from)
                     : lines == RowLines::tetgen_neigh ? static_cast<const void*>(rows.neighbours.data() + from)
                                                       : static_cast<const void*>(rows.tets.data() + from);
  return {data, n, static_cast<std::int64_t>(from), number_from, rows.region.data() + from};
}

std::string text_of(RowLines lines, const RowsToFormat& rows) {
  std::string text;
  append_row_lines(text, lines, rows);
  return text;
}

TEST(RowLines, AStringAndAFileGetTheSameBytes) {
  const Rows rows = random_rows(5000);
  const std::string path = test::temp_dir("row_lines") + "/rows";
  for (RowLines lines : kAllKinds) {
    {
      BufferedFile out(path);
      write_row_lines(out, lines, run(lines, rows, 0, rows.tets.size(), 11));
      out.close();
    }
    std::ifstream in(path, std::ios::binary);
    const std::string written{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    EXPECT_FALSE(written.empty());
    EXPECT_EQ(written, text_of(lines, run(lines, rows, 0, rows.tets.size(), 11))) << static_cast<int>(lines);
  }
}

TEST(RowLines, RunsCutAnywhereJoinToTheWhole) {
  const Rows rows = random_rows(1000);
  for (RowLines lines : kAllKinds)
    for (std::size_t cut : {std::size_t{0}, std::size_t{1}, std::size_t{377}, std::size_t{1000}}) {
      const std::string whole = text_of(lines, run(lines, rows, 0, 1000, 5));
      const std::string joined =
          text_of(lines, run(lines, rows, 0, cut, 5)) + text_of(lines, run(lines, rows, cut, 1000 - cut, 5));
      EXPECT_EQ(whole, joined) << static_cast<int>(lines) << " cut at " << cut;
    }
}

TEST(RowLines, NumbersAreTheFilesRows) {
  Rows rows;
  rows.points = {{1.5, -2, 0.1}};
  rows.tets = {{0, 1, 2, 3}};
  rows.region = {4};
  RowsToFormat one = run(RowLines::msh_tet, rows, 0, 1, 100);
  one.first = 7;  // the file's row 7: MSH tag 107, TetGen index 7
  EXPECT_EQ(text_of(RowLines::msh_tet, one), "107 1 2 3 4 \n");
  EXPECT_EQ(text_of(RowLines::tetgen_ele, one), "7 0 1 2 3\n");
  EXPECT_EQ(text_of(RowLines::medit_tet, one), "1 2 3 4 4\n");
  one.data = rows.points.data();
  EXPECT_EQ(text_of(RowLines::medit_vertex, one), "1.5 -2 0.10000000000000001 0\n");
  EXPECT_EQ(text_of(RowLines::msh_node, one), "1.5 -2 0.10000000000000001 \n");
  EXPECT_EQ(text_of(RowLines::msh_node_binary, one).size(), 3 * sizeof(double));
  EXPECT_EQ(text_of(RowLines::msh_tet_binary, run(RowLines::msh_tet_binary, rows, 0, 1, 1)).size(),
            5 * sizeof(std::uint64_t));
}

// A spread mesh may have 2^31 tets or more (each block fewer): its .neigh rows name them in full,
// in every way a writer formats them (a string, a file, a sink a chunk at a time).
TEST(RowLines, NeighboursPastTwoToThe31AreWrittenInFull) {
  const std::int64_t first_row = std::int64_t{3} << 30;  // 3221225472: past INT32_MAX
  const std::vector<Tet> own{{1, -1, -1, 2}, {-1, 0, -1, -1}, {0, -1, -1, -1}};
  const std::vector<FaceAcross> across{{4 * 1 + 2, std::int64_t{5} << 31}, {4 * 2 + 1, 7}};
  const std::vector<NeighbourRow> rows = neighbour_rows(own, first_row, across, 0, own.size());
  const std::vector<NeighbourRow> expected{{first_row + 1, -1, -1, first_row + 2},
                                           {-1, first_row, std::int64_t{5} << 31, -1},
                                           {first_row, 7, -1, -1}};
  EXPECT_EQ(rows, expected);
  const std::vector<NeighbourRow> tail = neighbour_rows(own, first_row, across, 1, 2);  // a writer's later chunk
  EXPECT_EQ(tail, std::vector<NeighbourRow>(expected.begin() + 1, expected.end()));
  const RowsToFormat run{rows.data(), rows.size(), first_row, 0};
  const std::string text = text_of(RowLines::tetgen_neigh, run);
  EXPECT_EQ(text,
            "3221225472 3221225473 -1 -1 3221225474\n"
            "3221225473 -1 3221225472 10737418240 -1\n"
            "3221225474 3221225472 7 -1 -1\n");
  const std::string path = test::temp_dir("row_lines_wide") + "/neigh";
  {
    BufferedFile out(path);
    write_row_lines(out, RowLines::tetgen_neigh, run);
    out.close();
  }
  std::ifstream in(path, std::ios::binary);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()), text);
}

// A spread mesh may have 2^31 points or more (each block fewer): a bulk's tets in compact ids
// (its own Steiner points from 9 on, the mesh's from 3 * 2^31) and the band's (through a table)
// are written in the mesh's ids, in every tet format, as a string, a file and a sink.
TEST(RowLines, TetsOfPointsPastTwoToThe31AreWrittenInFull) {
  const std::int64_t first_point = std::int64_t{3} << 31;  // 6442450944
  Rows rows;
  rows.tets = {{0, 2, 9, 10}, {3, 8, 10, 4}};
  rows.region = {1, 2};
  RowsToFormat bulk = run(RowLines::tetgen_ele, rows, 0, 2, 100);
  bulk.ids = {9, first_point - 9, nullptr};
  EXPECT_EQ(text_of(RowLines::tetgen_ele, bulk), "0 0 2 6442450944 6442450945\n1 3 8 6442450945 4\n");
  EXPECT_EQ(text_of(RowLines::medit_tet, bulk), "1 3 6442450945 6442450946 1\n4 9 6442450946 5 2\n");
  EXPECT_EQ(text_of(RowLines::msh_tet, bulk), "100 1 3 6442450945 6442450946 \n101 4 9 6442450946 5 \n");
  const auto words = [](const std::string& bytes) {
    std::vector<std::int64_t> values(bytes.size() / 8);
    std::memcpy(values.data(), bytes.data(), 8 * values.size());
    return values;
  };
  EXPECT_EQ(words(text_of(RowLines::msh_tet_binary, bulk)),
            (std::vector<std::int64_t>{100, 1, 3, first_point + 1, first_point + 2, 101, 4, 9, first_point + 2, 5}));
  EXPECT_EQ(words(text_of(RowLines::vtu_connectivity, bulk)),
            (std::vector<std::int64_t>{0, 2, first_point, first_point + 1, 3, 8, first_point + 1, 4}));
  // The band: ids from 2 through its table.
  const std::vector<std::int64_t> table{std::int64_t{5} << 32, (std::int64_t{5} << 32) + 3};
  Rows band;
  band.tets = {{0, 1, 2, 3}};
  RowsToFormat through_table = run(RowLines::tetgen_ele, band, 0, 1);
  through_table.ids = {2, 0, table.data()};
  EXPECT_EQ(text_of(RowLines::tetgen_ele, through_table), "0 0 1 21474836480 21474836483\n");
  // Ids that fit 32 bits give the text of the same tets in the mesh's ids (TetGen's own formatter).
  Rows near = rows;
  for (Tet& t : near.tets)
    for (std::int32_t& v : t) v = v < 9 ? v : v + 91;
  RowsToFormat shifted = run(RowLines::tetgen_ele, rows, 0, 2);
  shifted.ids = {9, 91, nullptr};
  for (RowLines lines : {RowLines::tetgen_ele, RowLines::medit_tet, RowLines::msh_tet, RowLines::vtu_connectivity})
    EXPECT_EQ(text_of(lines, shifted), text_of(lines, run(lines, near, 0, 2))) << static_cast<int>(lines);
  // A file and a sink (a chunk of 2^16 rows at a time) get the string's bytes.
  Rows many;
  for (std::int32_t i = 0; i < 70000; ++i) many.tets.push_back({i % 9, (i + 1) % 9, 9 + i % 50, 9 + (i + 7) % 50});
  RowsToFormat all = run(RowLines::tetgen_ele, many, 0, many.tets.size());
  all.ids = {9, first_point - 9, nullptr};
  struct Collected : ByteSink {
    std::string text;
    void bytes(const void* data, std::size_t size) override { text.append(static_cast<const char*>(data), size); }
  } sink;
  write_row_lines(sink, RowLines::tetgen_ele, all);
  const std::string path = test::temp_dir("row_lines_points") + "/ele";
  {
    BufferedFile out(path);
    write_row_lines(out, RowLines::tetgen_ele, all);
    out.close();
  }
  std::ifstream in(path, std::ios::binary);
  const std::string text = text_of(RowLines::tetgen_ele, all);
  EXPECT_EQ(sink.text, text);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()), text);
}

// A sink takes the rows a chunk (2^16 rows) at a time: the 64-bit .neigh rows are cut where they
// begin, as the others are.
TEST(RowLines, ASinkGetsTheSameBytesInChunks) {
  struct Collected : ByteSink {
    std::string text;
    void bytes(const void* data, std::size_t size) override { text.append(static_cast<const char*>(data), size); }
  };
  const Rows rows = random_rows(70000);
  for (RowLines lines : kAllKinds) {
    Collected sink;
    write_row_lines(sink, lines, run(lines, rows, 0, rows.tets.size(), 3));
    EXPECT_EQ(sink.text, text_of(lines, run(lines, rows, 0, rows.tets.size(), 3))) << static_cast<int>(lines);
  }
}

}  // namespace
}  // namespace partet
