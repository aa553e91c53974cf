// Reading back the VTK and MEDIT files partet writes (io/mesh_read.hpp): the same points, tets and
// boundary as written, a .pvtu set joined by its GlobalPointIds, and files partet does not write
// refused with a message. (The check of whole runs, on one and several ranks, is
// tests/formats/check_vtk_medit.sh.)
#include "io/mesh_read.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <string>

#include "io/mesh_formats.hpp"
#include "io/output_set.hpp"
#include "partet/errors.hpp"
#include "test_support.hpp"
#include "two_tets.hpp"

namespace partet {
namespace {

using test::TwoTets;

// The files of one format at prefix, published as a run publishes them.
void write_format(const TwoTets& m, MeshFormat format, const std::string& prefix) {
  OutputSet set(journal_path(prefix));
  add_mesh_files(set, format, m.output(), prefix, RankWriters{});
  set.publish();
}

// The same points in the same numbering, and the same tets (a .pvtu set gives them piece by piece).
void expect_same_mesh(const TwoTets& m, const TetgenFileSet& read) {
  EXPECT_EQ(read.mesh.points, m.mesh.points);
  std::vector<Tet> written = m.mesh.tets, given = read.mesh.tets;
  std::sort(written.begin(), written.end());
  std::sort(given.begin(), given.end());
  EXPECT_EQ(given, written);
  EXPECT_EQ(read.mesh.neighbours.size(), read.mesh.tets.size());
}

TEST(MeshRead, ASingleVtuGivesItsPointsAndTetsAndNoBoundaryList) {
  const TwoTets m;
  const std::string prefix = test::temp_dir("mesh_read_vtu") + "/m";
  write_format(m, MeshFormat::vtu, prefix);
  ASSERT_TRUE(reads_mesh_file(prefix + ".vtu"));
  EXPECT_FALSE(lists_boundary(prefix + ".vtu"));
  const TetgenFileSet read = read_mesh_set(prefix + ".vtu");
  expect_same_mesh(m, read);
  EXPECT_FALSE(read.has_faces);
}

// Each piece file numbers its points from 0; GlobalPointIds puts them back in the whole mesh's
// numbering, and the points two files share (the tets' common face) are given once.
TEST(MeshRead, APvtuSetIsJoinedByItsGlobalPointIds) {
  const TwoTets m;
  const std::string prefix = test::temp_dir("mesh_read_pvtu") + "/m";
  write_format(m, MeshFormat::pvtu, prefix);
  MeshPart index;
  const std::vector<std::string> files = read_named_mesh_file(prefix + ".pvtu", index);
  EXPECT_EQ(files, (std::vector<std::string>{prefix + ".pvtu", prefix + "_seams.vtu", prefix + "_p0.vtu"}));
  EXPECT_TRUE(index.nodes.empty());  // the index holds no cells
  MeshPart seams;
  read_set_file(prefix + ".pvtu", files[1], seams);
  EXPECT_EQ(seams.node_ids, (std::vector<MeshId>{1, 4, 2, 3}));  // in order of first use
  ASSERT_EQ(seams.tets.size(), 1u);
  EXPECT_EQ(seams.tets[0], (std::array<MeshId, 4>{1, 4, 2, 3}));
  expect_same_mesh(m, read_mesh_set(prefix + ".pvtu"));
}

TEST(MeshRead, AMeditFileGivesItsBoundaryWithTheSplitPartsMarked) {
  const TwoTets m;
  const std::string prefix = test::temp_dir("mesh_read_medit") + "/m";
  write_format(m, MeshFormat::medit, prefix);
  const TetgenFileSet read = read_mesh_set(prefix + ".mesh");
  expect_same_mesh(m, read);
  EXPECT_TRUE(read.has_faces && read.faces_outward);
  EXPECT_EQ(read.faces, m.boundary);
  MeshPart part;
  read_named_mesh_file(prefix + ".mesh", part);
  EXPECT_EQ(part.markers, (std::vector<std::int32_t>{1, 1, 1, 1, 1, 2}));
}

TEST(MeshRead, RefusesFilesPartetDoesNotWrite) {
  const std::string dir = test::temp_dir("mesh_read_foreign");
  std::ofstream(dir + "/ascii.vtu") << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\">\n"
                                       "<UnstructuredGrid><Piece NumberOfPoints=\"0\" NumberOfCells=\"0\"/>"
                                       "</UnstructuredGrid></VTKFile>\n";
  EXPECT_TRUE(test::contains(test::input_error([&] { read_mesh_set(dir + "/ascii.vtu"); }), "raw appended data"));
  std::ofstream(dir + "/grid.pvtu") << "<VTKFile type=\"PStructuredGrid\"></VTKFile>\n";
  EXPECT_TRUE(test::contains(test::input_error([&] { read_mesh_set(dir + "/grid.pvtu"); }), "not a .pvtu index"));
  std::ofstream(dir + "/edges.mesh") << "MeshVersionFormatted 2\nDimension 3\nEdges\n0\nEnd\n";
  EXPECT_TRUE(test::contains(test::input_error([&] { read_mesh_set(dir + "/edges.mesh"); }),
                             "section 'Edges', which partet does not write"));
  EXPECT_TRUE(test::contains(test::input_error([&] { read_mesh_set(dir + "/missing.mesh"); }), "cannot open"));
}

}  // namespace
}  // namespace partet
