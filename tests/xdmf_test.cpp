// The XDMF set's pieces that need no MPI: the blocks ranks write, their bytes, the XDMF text.
// (The collective HDF5 write is tested under mpiexec by tests/formats/formats.sh.)
#include "io/xdmf.hpp"

#include <gtest/gtest.h>

#include "partet/errors.hpp"
#include "test_support.hpp"

namespace partet {
namespace {

// Two tets sharing face (1,2,3), with its five outer faces as the boundary (the last one split).
struct TwoTets {
  TetMesh mesh;
  std::vector<Triangle> boundary;
  TwoTets() {
    mesh.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
    mesh.tets = {{0, 1, 2, 3}, {1, 4, 2, 3}};
    mesh.piece = {0, -1};
    boundary = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 4}, {1, 4, 3}, {2, 3, 4}};
  }
  MeshOutput output() const { return MeshOutput{mesh, boundary, 5}; }
};

TEST(MeshBlock, BlocksInOrderMakeTheWholeArrays) {
  const TwoTets m;
  const std::vector<std::int32_t> region = region_of_tets(m.mesh);
  for (int parts = 1; parts <= 7; ++parts) {
    MeshBlock all;
    for (int part = 0; part < parts; ++part) {
      const MeshBlock b = mesh_block(m.output(), region, part, parts);
      all.points.insert(all.points.end(), b.points.begin(), b.points.end());
      all.tets.insert(all.tets.end(), b.tets.begin(), b.tets.end());
      all.tet_piece.insert(all.tet_piece.end(), b.tet_piece.begin(), b.tet_piece.end());
      all.tet_region.insert(all.tet_region.end(), b.tet_region.begin(), b.tet_region.end());
      all.faces.insert(all.faces.end(), b.faces.begin(), b.faces.end());
      all.face_marker.insert(all.face_marker.end(), b.face_marker.begin(), b.face_marker.end());
    }
    EXPECT_EQ(all.points, m.mesh.points) << parts << " parts";
    ASSERT_EQ(all.tets.size(), 2u);
    EXPECT_EQ(all.tets[1], (std::array<std::int64_t, 4>{1, 4, 2, 3}));
    EXPECT_EQ(all.tet_piece, (std::vector<std::int32_t>{0, -1}));
    EXPECT_EQ(all.tet_region, (std::vector<std::int32_t>{1, 1}));  // one connected solid
    ASSERT_EQ(all.faces.size(), 6u);
    EXPECT_EQ(all.faces[3], (std::array<std::int64_t, 3>{1, 2, 4}));
    EXPECT_EQ(all.face_marker, (std::vector<std::int32_t>{1, 1, 1, 1, 1, 2}));  // the split part: 2
  }
}

TEST(MeshBlock, BytesRoundTripAndTruncatedBytesAreRefused) {
  const TwoTets m;
  const MeshBlock block = mesh_block(m.output(), region_of_tets(m.mesh), 0, 1);
  const std::string bytes = block_bytes(block);
  const MeshBlock back = block_from_bytes(bytes);
  EXPECT_EQ(back.points, block.points);
  EXPECT_EQ(back.tets, block.tets);
  EXPECT_EQ(back.faces, block.faces);
  EXPECT_EQ(back.face_marker, block.face_marker);
  EXPECT_EQ(back.tet_piece, block.tet_piece);
  EXPECT_THROW(block_from_bytes(std::string_view(bytes).substr(0, bytes.size() - 1)), InternalError);
  EXPECT_THROW(block_from_bytes(bytes + "x"), InternalError);
  EXPECT_EQ(block_from_bytes(block_bytes(MeshBlock{})).tets.size(), 0u);
}

TEST(XdmfText, NamesTheCountsAnd64BitDatasetsOfTheHdf5File) {
  const MeshTotals totals{5000000000ull, 3000000000ull, 7};  // above 2^31: 64-bit all the way
  const std::string mesh = xdmf_mesh_text(totals, "m.h5");
  EXPECT_TRUE(test::contains(mesh, "<Grid Name=\"mesh\""));
  EXPECT_TRUE(test::contains(mesh, "TopologyType=\"Tetrahedron\" NumberOfElements=\"3000000000\""));
  EXPECT_TRUE(test::contains(mesh, "Dimensions=\"3000000000 4\" NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">"
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
