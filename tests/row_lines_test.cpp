// The rows of the single-file formats: a string and a file get the same bytes, runs cut anywhere
// join to the whole, and the numbers are those of the file's rows.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "io/buffered_file.hpp"
#include "io/row_lines.hpp"
#include "test_support.hpp"

namespace partet {
namespace {

constexpr RowLines kAllKinds[] = {RowLines::tetgen_node,  RowLines::tetgen_ele,      RowLines::tetgen_neigh,
                                  RowLines::medit_vertex, RowLines::medit_tet,       RowLines::msh_node,
                                  RowLines::msh_tet,      RowLines::msh_node_binary, RowLines::msh_tet_binary};

struct Rows {
  std::vector<Point3> points;
  std::vector<Tet> tets;
  std::vector<std::int32_t> region;
};

Rows random_rows(std::size_t n) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-1e3, 1e3);
  std::uniform_int_distribution<std::int32_t> id(-1, 1 << 30);
  Rows rows;
  for (std::size_t i = 0; i < n; ++i) {
    rows.points.push_back({coordinate(random), coordinate(random), coordinate(random)});
    rows.tets.push_back({id(random), id(random), id(random), id(random)});
    rows.region.push_back(1 + static_cast<std::int32_t>(i % 3));
  }
  return rows;
}

// Rows [from, from + n) of `rows` as the kind formats them, row `from` being the file's row `first`.
RowsToFormat run(RowLines lines, const Rows& rows, std::size_t from, std::size_t n, std::int64_t number_from = 0) {
  const void* data = formats_points(lines) ? static_cast<const void*>(rows.points.data() + from)
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

}  // namespace
}  // namespace partet
