// The XDMF set's pieces that need no MPI: the blocks ranks write, the XDMF text.
// (The collective HDF5 write is tested under mpiexec by tests/formats/formats.sh.)
#include "io/xdmf.hpp"

#include <gtest/gtest.h>

#include "partet/errors.hpp"
#include "test_support.hpp"
#include "two_tets.hpp"

namespace partet {
namespace {

using test::TwoTets;

template <class T>
void append(std::vector<T>& all, const ArrayRun<T>& run) {
  all.insert(all.end(), run.data, run.data + run.size);
}

// Every rank's block, in rank order, makes the whole arrays, for any number of ranks.
TEST(MeshBlockView, BlocksInOrderMakeTheWholeArrays) {
  const TwoTets m;
  const std::vector<std::int32_t> region = region_of_tets(m.mesh);
  for (int parts = 1; parts <= 7; ++parts) {
    std::vector<Point3> points;
    std::vector<Tet> tets;
    std::vector<Triangle> faces;
    std::vector<std::int32_t> piece, tet_region, marker;
    for (int part = 0; part < parts; ++part) {
      MadeColumns made;
      const MeshBlockView b = mesh_block_view(m.output(), region, part, parts, made);
      append(points, b.points), append(tets, b.tets), append(piece, b.tet_piece);
      append(tet_region, b.tet_region), append(faces, b.faces), append(marker, b.face_marker);
    }
    EXPECT_EQ(points, m.mesh.points) << parts << " parts";
    EXPECT_EQ(tets, m.mesh.tets);
    EXPECT_EQ(piece, (std::vector<std::int32_t>{0, -1}));
    EXPECT_EQ(tet_region, (std::vector<std::int32_t>{1, 1}));  // one connected solid
    EXPECT_EQ(faces, m.boundary);
    EXPECT_EQ(marker, (std::vector<std::int32_t>{1, 1, 1, 1, 1, 2}));  // the split part: 2
  }
}

// The block views the mesh's arrays where they are; only the columns it lacks are made.
TEST(MeshBlockView, ViewsTheMeshAndMakesOnlyWhatItLacks) {
  TwoTets m;
  const std::vector<std::int32_t> region = region_of_tets(m.mesh);
  MadeColumns made;
  MeshBlockView b = mesh_block_view(m.output(), region, 1, 2, made);
  EXPECT_EQ(b.points.data, m.mesh.points.data() + 2);
  EXPECT_EQ(b.tets.data, m.mesh.tets.data() + 1);
  EXPECT_EQ(b.tet_piece.data, m.mesh.piece.data() + 1);
  EXPECT_TRUE(made.piece.empty());
  m.mesh.piece.clear();  // a mesh without piece numbers: -1 for each tet of the run
  b = mesh_block_view(m.output(), region, 0, 1, made);
  ASSERT_EQ(b.tet_piece.size, 2u);
  EXPECT_EQ(b.tet_piece.data, made.piece.data());
  EXPECT_EQ(made.piece, (std::vector<std::int32_t>{-1, -1}));
}

TEST(XdmfText, NamesTheCountsAnd64BitDatasetsOfTheHdf5File) {
  const MeshTotals totals{5000000000ull, 3000000000ull, 7};  // above 2^31: 64-bit all the way
  const std::string mesh = xdmf_mesh_text(totals, "m.h5");
  EXPECT_TRUE(test::contains(mesh, "<Grid Name=\"mesh\""));
  EXPECT_TRUE(test::contains(mesh, "TopologyType=\"Tetrahedron\" NumberOfElements=\"3000000000\""));
  EXPECT_TRUE(test::contains(mesh,
                             "Dimensions=\"3000000000 4\" NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">"
                             "m.h5:/Mesh/mesh/topology<"));
  EXPECT_TRUE(test::contains(mesh, "Dimensions=\"5000000000 3\" NumberType=\"Float\" Precision=\"8\""));
  EXPECT_TRUE(test::contains(mesh, "<Attribute Name=\"region\""));
  const std::string boundary = xdmf_boundary_text(totals, "m.h5", "m_boundary.h5");
  EXPECT_TRUE(test::contains(boundary, "<Grid Name=\"boundary\""));
  EXPECT_TRUE(test::contains(boundary, "TopologyType=\"Triangle\" NumberOfElements=\"7\""));
  EXPECT_TRUE(test::contains(boundary, ">m_boundary.h5:/MeshTags/boundary/values<"));
  EXPECT_TRUE(test::contains(boundary, ">m.h5:/Mesh/mesh/geometry<"));  // the points are the mesh's
  EXPECT_EQ(xdmf_paths("out/m"),
            (std::vector<std::string>{"out/m.xdmf", "out/m_boundary.xdmf", "out/m.h5", "out/m_boundary.h5"}));
}

}  // namespace
}  // namespace partet
