// TetGen file writing and reading: exact round trip, TetGen's conventions, errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "partet/errors.hpp"
#include "io/buffered_file.hpp"
#include "io/output_set.hpp"
#include "io/tetgen_files.hpp"
#include "test_support.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

// The TetGen files of a mesh, published at once, as a run publishes its set.
void write_tetgen_files(const TetMesh& mesh, const std::vector<Triangle>& faces, const std::string& prefix) {
  OutputSet set(journal_path(prefix));
  add_tetgen_files(set, mesh, faces, prefix);
  set.publish();
}

namespace fs = std::filesystem;

// Unit cube (corner index = x + 2y + 4z) split into six positive tets along the 0-7 diagonal.
TetMesh cube_mesh() {
  TetMesh m;
  for (int i = 0; i < 8; ++i) m.points.push_back({double(i & 1), double((i >> 1) & 1), double((i >> 2) & 1)});
  m.tets = {{0, 1, 3, 7}, {0, 1, 7, 5}, {0, 2, 7, 3}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 7, 6}};
  return m;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void write_text(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

std::string first_line(const std::string& path) {
  std::string text = read_text(path);
  return text.substr(0, text.find('\n'));
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Temporaries and set-aside files of a publish (".tmp-PID-RANDOM", ".old.tmp-...").
std::vector<std::string> tmp_files(const std::string& dir) {
  std::vector<std::string> found;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().filename().string().find(".tmp") != std::string::npos) found.push_back(entry.path().string());
  return found;
}

// Every neighbour relation is symmetric and joins tets that share exactly three vertices
// across the face opposite the given corner.
void expect_consistent_neighbours(const TetMesh& m) {
  ASSERT_EQ(m.neighbours.size(), m.tets.size());
  for (std::size_t t = 0; t < m.tets.size(); ++t)
    for (int j = 0; j < 4; ++j) {
      std::int32_t n = m.neighbours[t][j];
      if (n < 0) continue;
      int shared = 0;
      bool opposite_shared = false;
      for (std::int32_t a : m.tets[t])
        for (std::int32_t b : m.tets[n])
          if (a == b) {
            ++shared;
            if (a == m.tets[t][j]) opposite_shared = true;
          }
      EXPECT_EQ(shared, 3) << "tet " << t << " corner " << j;
      EXPECT_FALSE(opposite_shared);
      bool back = false;
      for (int k = 0; k < 4; ++k) back = back || m.neighbours[n][k] == std::int32_t(t);
      EXPECT_TRUE(back);
    }
}

TEST(TetgenFiles, RoundTripIsBitIdentical) {
  std::string dir = test::temp_dir("tetgen_round_trip");
  TetMesh m = cube_mesh();
  m.points[0] = {0.1, 1.0 / 3.0, 1e-300};
  m.points[1] = {-2.5e17, std::nextafter(1.0, 2.0), -0.0};
  m.points[2] = {4.9406564584124654e-324, 1.7976931348623157e308, -1.0 / 7.0};
  m.neighbours.assign(m.tets.size(), Tet{-1, -1, -1, -1});
  std::vector<Triangle> faces = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}};
  write_tetgen_files(m, faces, dir + "/mesh");

  EXPECT_EQ(first_line(dir + "/mesh.node"), "8 3 0 0");
  EXPECT_EQ(first_line(dir + "/mesh.ele"), "6 4 0");
  EXPECT_EQ(first_line(dir + "/mesh.face"), "3 1");
  EXPECT_EQ(first_line(dir + "/mesh.neigh"), "6 4");
  // Rows are 0-based, and coordinates are printed as %.17g would.
  std::string node = read_text(dir + "/mesh.node");
  EXPECT_NE(node.find("\n0 0.10000000000000001 0.33333333333333331 1e-300\n1 -2.5e+17 "), std::string::npos) << node;
  EXPECT_NE(read_text(dir + "/mesh.ele").find("\n0 0 1 3 7\n"), std::string::npos);
  EXPECT_NE(read_text(dir + "/mesh.face").find("\n2 4 5 7 1\n"), std::string::npos);
  EXPECT_NE(read_text(dir + "/mesh.neigh").find("\n5 -1 -1 -1 -1\n"), std::string::npos);
  EXPECT_TRUE(tmp_files(dir).empty());

  std::vector<Triangle> faces_back;
  TetMesh back = read_tetgen_files(dir + "/mesh", &faces_back);
  ASSERT_EQ(back.points.size(), m.points.size());
  for (std::size_t i = 0; i < m.points.size(); ++i)
    for (int k = 0; k < 3; ++k)
      EXPECT_TRUE(same_bits(back.points[i][k], m.points[i][k])) << "point " << i << " coordinate " << k;
  EXPECT_EQ(back.tets, m.tets);
  EXPECT_EQ(faces_back, faces);
}

TEST(TetgenFiles, NeighboursAreComputedOnRead) {
  std::string dir = test::temp_dir("tetgen_neighbours");
  TetMesh m = cube_mesh();
  write_tetgen_files(m, {}, dir + "/cube");  // no neighbours given: written as -1
  TetMesh back = read_tetgen_files(dir + "/cube");
  expect_consistent_neighbours(back);
  // Each Kuhn tet has two interior faces (to its neighbours around the diagonal) and two on the
  // cube's surface.
  for (const Tet& n : back.neighbours) EXPECT_EQ(std::count(n.begin(), n.end(), -1), 2);
  // Tet 0 = (0,1,3,7): the face opposite vertex 1, (0,3,7), is shared with tet 2 = (0,2,7,3).
  EXPECT_EQ(back.neighbours[0][1], 2);

  // The computed neighbours are what gets written.
  write_tetgen_files(back, {}, dir + "/again");
  std::string neigh = read_text(dir + "/again.neigh");
  EXPECT_NE(neigh.find("\n0 -1 2 1 -1\n"), std::string::npos) << neigh;
}

TEST(TetgenFiles, ReadsOneBasedWithCommentsAndExtraColumns) {
  std::string dir = test::temp_dir("tetgen_one_based");
  write_text(dir + "/m.node",
             "# written by hand\n"
             "5  3  1  1\n"
             "1 0 0 0 7.5 1\n"
             "\n"
             "2 1 0 0 7.5 1  # with a comment\n"
             "3 0 1 0 7.5 0\n"
             "  4\t0 0 1 7.5 0\r\n"
             "5 1 1 1 0.0 0\n");
  write_text(dir + "/m.ele",
             "2 4 1\n"
             "1 1 2 3 4 10\n"
             "2 2 5 3 4 11\n");
  write_text(dir + "/m.face",
             "# faces\n"
             "2 1\n"
             "1 1 3 2 -1\n"
             "2 1 2 4 -1\n");
  std::vector<Triangle> faces;
  TetMesh m = read_tetgen_files(dir + "/m", &faces);
  ASSERT_EQ(m.points.size(), 5u);
  EXPECT_EQ(m.points[3], (Point3{0, 0, 1}));
  EXPECT_EQ(m.tets, (std::vector<Tet>{{0, 1, 2, 3}, {1, 4, 2, 3}}));
  EXPECT_EQ(faces, (std::vector<Triangle>{{0, 2, 1}, {0, 1, 3}}));
  ASSERT_EQ(m.neighbours.size(), 2u);
  EXPECT_EQ(m.neighbours[0], (Tet{1, -1, -1, -1}));
  EXPECT_EQ(m.neighbours[1], (Tet{-1, 0, -1, -1}));
}

TEST(TetgenFiles, MissingFaceFileGivesNoFaces) {
  std::string dir = test::temp_dir("tetgen_no_face");
  write_tetgen_files(cube_mesh(), {{0, 2, 3}}, dir + "/m");
  fs::remove(dir + "/m.face");
  std::vector<Triangle> faces = {{9, 9, 9}};
  TetMesh m = read_tetgen_files(dir + "/m", &faces);
  EXPECT_EQ(m.tets.size(), 6u);
  EXPECT_TRUE(faces.empty());
}

// Runs the reader and returns the InputError message ("" if nothing was thrown).
std::string read_error(const std::string& prefix) {
  try {
    read_tetgen_files(prefix);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(TetgenFiles, MalformedContentNamesFileAndLine) {
  std::string dir = test::temp_dir("tetgen_malformed");
  std::string prefix = dir + "/bad";
  write_text(prefix + ".ele", "1 4 0\n0 0 1 2 3\n");

  write_text(prefix + ".node", "# header next\n4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1x 0\n3 0 0 1\n");
  std::string message = read_error(prefix);
  EXPECT_NE(message.find(prefix + ".node line 5"), std::string::npos) << message;
  EXPECT_NE(message.find("'1x'"), std::string::npos) << message;

  write_text(prefix + ".node", "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1\n3 0 0 1\n");
  message = read_error(prefix);
  EXPECT_NE(message.find(prefix + ".node line 4: missing coordinate"), std::string::npos) << message;

  write_text(prefix + ".node", "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n");
  message = read_error(prefix);
  EXPECT_NE(message.find("unexpected end of file"), std::string::npos) << message;

  write_text(prefix + ".node", "4 3 0 0\n0 0 0 0\n1 1 0 0\n3 0 1 0\n3 0 0 1\n");
  message = read_error(prefix);
  EXPECT_NE(message.find("line 4: expected index 2, found 3"), std::string::npos) << message;

  write_text(prefix + ".node", "4 3 0 0\n0 0 0 0\n1 1 0 nan\n2 0 1 0\n3 0 0 1\n");
  message = read_error(prefix);
  EXPECT_NE(message.find("line 3: non-finite coordinate"), std::string::npos) << message;

  write_text(prefix + ".node", "4 2 0 0\n");
  message = read_error(prefix);
  EXPECT_NE(message.find("dimension must be 3"), std::string::npos) << message;

  write_text(prefix + ".node", "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n");
  EXPECT_EQ(read_error(prefix), "");
  write_text(prefix + ".ele", "1 4 0\n0 0 1 2 4\n");
  message = read_error(prefix);
  EXPECT_NE(message.find(prefix + ".ele line 2: vertex index 4 out of range"), std::string::npos) << message;

  message = read_error(dir + "/does_not_exist");
  EXPECT_NE(message.find("cannot open " + dir + "/does_not_exist.node"), std::string::npos) << message;
}

TEST(TetgenFiles, WriteFailureThrowsAndLeavesNoTemporaries) {
  std::string dir = test::temp_dir("tetgen_write_fail");
  EXPECT_THROW(write_tetgen_files(cube_mesh(), {}, dir + "/missing_dir/m"), OutputError);
  // A directory where the last file must go: writing works, moving it into place fails, and
  // nothing of the new set may stay behind.
  fs::create_directories(dir + "/m.neigh/inside");
  try {
    write_tetgen_files(cube_mesh(), {}, dir + "/m");
    ADD_FAILURE() << "expected OutputError";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("'" + dir + "/m.neigh'"), std::string::npos) << e.what();
  }
  fs::remove_all(dir + "/m.neigh");
  EXPECT_TRUE(tmp_files(dir).empty());
  EXPECT_FALSE(fs::exists(dir + "/m.node"));  // nothing moved in after a failure
}

TEST(TetgenFiles, FailedPublishKeepsThePreviousSet) {
  std::string dir = test::temp_dir("tetgen_publish_fail");
  const TetMesh first = cube_mesh();
  write_tetgen_files(first, {}, dir + "/m");
  auto contents = [&] {
    std::string all;
    for (const char* ext : {".node", ".ele", ".face", ".neigh"}) {
      std::ifstream in(dir + "/m" + ext, std::ios::binary);
      all += std::string(std::istreambuf_iterator<char>(in), {}) + "|";
    }
    return all;
  };
  const std::string before = contents();
  TetMesh second = first;
  second.points[0][0] += 0.5;
  for (int failing = 1; failing <= 4; ++failing) {
    SCOPED_TRACE("move " + std::to_string(failing) + " fails");
    ::setenv("PARTET_INJECT_PUBLISH_FAILURE", std::to_string(failing).c_str(), 1);
    EXPECT_THROW(write_tetgen_files(second, {}, dir + "/m"), OutputError);
    ::unsetenv("PARTET_INJECT_PUBLISH_FAILURE");
    EXPECT_EQ(contents(), before);
    EXPECT_TRUE(tmp_files(dir).empty());
  }
  write_tetgen_files(second, {}, dir + "/m");
  EXPECT_NE(contents(), before);
}

TEST(TetgenFiles, EveryFileOfASetCarriesTheSameId) {
  std::string dir = test::temp_dir("tetgen_ids");
  TetMesh a = cube_mesh(), b = cube_mesh();
  a.neighbours = compute_neighbours(a.tets);
  b.points[1][1] += 0.25;
  write_tetgen_files(a, {}, dir + "/a");
  write_tetgen_files(b, {}, dir + "/b");
  const TetgenFileSet set = read_tetgen_set(dir + "/a");
  ASSERT_EQ(set.ids.size(), 4u);
  for (const auto& [file, id] : set.ids) EXPECT_EQ(id, mesh_id(a, {})) << file;
  EXPECT_NE(mesh_id(a, {}), mesh_id(b, {}));
  EXPECT_TRUE(set.has_faces);
  EXPECT_TRUE(set.has_neighbours);
  EXPECT_EQ(set.neighbours, set.mesh.neighbours);
}

// The ID of a mesh whose rows are kept in parts (a spread mesh's owners): the fingerprints of the
// runs, joined in row order, give the whole arrays' fingerprint wherever the arrays are cut, and
// the set's ID; another order or a changed row gives another.
TEST(TetgenFiles, FingerprintsOfRunsJoinedInOrderGiveTheWholeSetsId) {
  TetMesh mesh = cube_mesh();
  const std::vector<Triangle> faces = {{0, 1, 2}, {2, 3, 0}, {4, 5, 6}};
  const auto of = [](TetgenFile file, const auto& rows, std::size_t from, std::size_t to) {
    return fingerprint_rows(file, reinterpret_cast<const char*>(rows.data() + from), to - from);
  };
  const auto joined = [&](TetgenFile file, const auto& rows, std::size_t cut) {
    return combine(of(file, rows, 0, cut), of(file, rows, cut, rows.size()));
  };
  const RowsFingerprint points = of(TetgenFile::node, mesh.points, 0, mesh.points.size());
  const RowsFingerprint tets = of(TetgenFile::ele, mesh.tets, 0, mesh.tets.size());
  const RowsFingerprint triangles = of(TetgenFile::face, faces, 0, faces.size());
  EXPECT_EQ(mesh_id(points, tets, triangles), mesh_id(mesh, faces));
  for (std::size_t cut = 0; cut <= mesh.points.size(); ++cut) {
    const RowsFingerprint p = joined(TetgenFile::node, mesh.points, cut);
    EXPECT_EQ(p.hash, points.hash) << cut;
    EXPECT_EQ(p.words, points.words) << cut;
  }
  for (std::size_t cut = 0; cut <= mesh.tets.size(); ++cut)
    EXPECT_EQ(mesh_id(points, joined(TetgenFile::ele, mesh.tets, cut), triangles), mesh_id(mesh, faces)) << cut;
  for (std::size_t cut = 0; cut <= faces.size(); ++cut)
    EXPECT_EQ(mesh_id(points, tets, joined(TetgenFile::face, faces, cut)), mesh_id(mesh, faces)) << cut;
  // Three runs, joined left to right or right first: the same.
  const RowsFingerprint a = of(TetgenFile::node, mesh.points, 0, 2), b = of(TetgenFile::node, mesh.points, 2, 5),
                        c = of(TetgenFile::node, mesh.points, 5, mesh.points.size());
  EXPECT_EQ(combine(combine(a, b), c).hash, combine(a, combine(b, c)).hash);
  EXPECT_NE(combine(b, a).hash, combine(a, b).hash);
  std::swap(mesh.tets[0], mesh.tets[1]);
  EXPECT_NE(mesh_id(mesh, faces), mesh_id(points, tets, triangles));
}

// A block's tets in compact ids have the fingerprint of their rows in the mesh's ids: the same as
// the packed rows below 2^31 (so a spread mesh's ID is the assembled mesh's), and past 2^32 the
// high bits count.
TEST(TetgenFiles, TetsInCompactIdsHaveTheFingerprintOfTheirRows) {
  std::vector<Tet> compact, mapped;
  for (std::int32_t i = 0; i < 3000; ++i) {  // past one block of the fingerprint's words
    compact.push_back({i % 9, (i * 7) % 9, 9 + i % 40, 9 + (i * 3) % 40});
    Tet& t = mapped.emplace_back(compact.back());
    for (std::int32_t& v : t) v = v < 9 ? v : v + 1000;
  }
  const RowsFingerprint through = fingerprint_tets(compact, {9, 1000, nullptr});
  const RowsFingerprint packed = fingerprint_rows(TetgenFile::ele, mapped);
  EXPECT_EQ(through.hash, packed.hash);
  EXPECT_EQ(through.words, packed.words);
  EXPECT_EQ(fingerprint_tets(mapped, {}).hash, packed.hash);
  // Past 2^32 the ids are not those of 2^32 less.
  const RowsFingerprint far = fingerprint_tets(compact, {9, (std::int64_t{1} << 32) + 1000, nullptr});
  EXPECT_NE(far.hash, through.hash);
  EXPECT_EQ(far.words, through.words);
}

TEST(TetgenFiles, LargeMeshRoundTrip) {
  // Enough rows to cross the write buffer's flush boundary many times.
  std::string dir = test::temp_dir("tetgen_large");
  TetMesh m;
  const int n = 200000;
  for (int i = 0; i < n; ++i) m.points.push_back({i * 0.1, 1.0 / (i + 1), -i * 1e-7});
  for (int i = 0; i + 3 < n; i += 2) m.tets.push_back({i, i + 1, i + 2, i + 3});
  write_tetgen_files(m, {}, dir + "/big");
  TetMesh back = read_tetgen_files(dir + "/big");
  ASSERT_EQ(back.points.size(), m.points.size());
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) ASSERT_TRUE(same_bits(back.points[i][k], m.points[i][k])) << i;
  EXPECT_EQ(back.tets, m.tets);
  expect_consistent_neighbours(back);
}

// Ranks format blocks of a file's lines (append_tetgen_lines) and rank 0 writes them in order
// (a TetgenLines): the files must be the same bytes as written alone, the .face markers included.
TEST(TetgenFiles, LinesFormattedInBlocksAreTheSameFile) {
  const std::string dir = test::temp_dir("tetgen_blocks");
  TetMesh m = cube_mesh();
  m.neighbours = compute_neighbours(m.tets);
  const std::vector<Triangle> faces = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}};
  const std::size_t split_from = 3;
  for (int blocks : {1, 2, 4, 7}) {
    const TetgenLines in_blocks = [blocks](const TetgenRows& rows, BufferedFile& out) {
      for (int b = 0; b < blocks; ++b) {
        const std::size_t first = rows.count * b / blocks, last = rows.count * (b + 1) / blocks;
        std::string text;
        append_tetgen_lines(text, rows.file, rows.data + first * row_bytes(rows.file), first, last - first,
                            rows.split_from);
        out.bytes(text.data(), text.size());
      }
    };
    for (TetgenFile file : {TetgenFile::node, TetgenFile::ele, TetgenFile::face, TetgenFile::neigh}) {
      const std::string alone = dir + "/alone" + extension(file), parts = dir + "/parts" + extension(file);
      write_tetgen_file(file, m, faces, "id", alone, alone, split_from);
      write_tetgen_file(file, m, faces, "id", parts, parts, split_from, in_blocks);
      EXPECT_EQ(read_text(alone), read_text(parts)) << extension(file) << " in " << blocks << " blocks";
    }
  }
  const std::string face = read_text(dir + "/alone.face");
  EXPECT_NE(face.find("2 4 5 7 1\n3 4 7 6 2\n"), std::string::npos) << face;
}

}  // namespace
}  // namespace partet
