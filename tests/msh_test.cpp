// The MSH partitions' arrays, which any rank writes a partition's file from. (gmsh reads the
// files in tests/formats/msh_parts.py.)
#include "io/msh.hpp"

#include <gtest/gtest.h>

#include <map>
#include <string>

#include "partet/errors.hpp"
#include "test_support.hpp"
#include "two_tets.hpp"

namespace partet {
namespace {

using test::TwoTets;

std::vector<std::uint64_t> values(const ArrayRun<std::uint64_t>& run) { return {run.data, run.data + run.size}; }

TEST(MshPartitions, PiecesInOrderThenTheSeams) {
  const TwoTets m;
  EXPECT_EQ(msh_partition_pieces(m.output()), (std::vector<int>{0, -1}));
}

// Each partition holds its tets and the boundary triangles they bound, under the single file's
// tags (triangles from 1, then the tets), with the nodes they use, ascending.
TEST(MshPartitions, EachPartitionHasItsTetsAndTheirBoundaryUnderTheSingleFilesTags) {
  const TwoTets m;
  MshPartitions partitions(m.output(), /*binary=*/true);
  const MshPartView first = partitions.of(0);
  EXPECT_EQ(values(first.about), (std::vector<std::uint64_t>{1, 2, 3, 1, 1}));
  EXPECT_EQ(values(first.node_tags), (std::vector<std::uint64_t>{1, 2, 3, 4}));
  EXPECT_EQ(values(first.tets), (std::vector<std::uint64_t>{7, 1, 2, 3, 4}));
  EXPECT_EQ(values(first.triangles), (std::vector<std::uint64_t>{1, 1, 3, 2, 2, 1, 2, 4, 3, 1, 4, 3}));
  EXPECT_EQ(first.xyz.size, 12u);
  EXPECT_EQ(first.xyz.data[3], 1.0);  // node 2 = point 1 = (1, 0, 0)
  const MshPartView seams = partitions.of(-1);
  // Two whole input triangles (tags 4 and 5), then the split part (tag 6).
  EXPECT_EQ(values(seams.about), (std::vector<std::uint64_t>{2, 2, 2, 1, 1}));
  EXPECT_EQ(values(seams.node_tags), (std::vector<std::uint64_t>{2, 3, 4, 5}));
  EXPECT_EQ(values(seams.tets), (std::vector<std::uint64_t>{8, 2, 5, 3, 4}));
  EXPECT_EQ(values(seams.triangles), (std::vector<std::uint64_t>{4, 2, 3, 5, 5, 2, 5, 4, 6, 3, 4, 5}));
  // Bounds: the whole mesh's, then the partition's.
  EXPECT_EQ(std::vector<double>(seams.box.data, seams.box.data + 12),
            (std::vector<double>{0, 0, 0, 1, 1, 1, 0, 0, 0, 1, 1, 1}));
  EXPECT_EQ(std::vector<double>(first.box.data + 6, first.box.data + 12), (std::vector<double>{0, 0, 0, 1, 1, 1}));
}

// With many partitions each uses few of the nodes: still its own, ascending, and its tets and
// boundary triangles.
TEST(MshPartitions, ManySmallPartitionsListTheirOwnNodesAscending) {
  TetMesh mesh;
  std::vector<Triangle> boundary;
  constexpr int kTets = 70;
  for (int i = 0; i < kTets; ++i) {
    const auto d = static_cast<double>(2 * i);
    mesh.points.insert(mesh.points.end(), {{d, 0, 0}, {d + 1, 0, 0}, {d, 1, 0}, {d, 0, 1}});
    const Tet t{4 * i + 3, 4 * i + 1, 4 * i + 2, 4 * i};
    mesh.tets.push_back(t);
    mesh.piece.push_back(kTets - 1 - i);  // pieces in the reverse order of the tets
    for (int j = 0; j < 4; ++j) boundary.push_back(outward_face(t, j));
  }
  const MeshOutput output{mesh, boundary};
  MshPartitions partitions(output, false);
  for (int piece = 0; piece < kTets; ++piece) {
    const int tet = kTets - 1 - piece;
    const MshPartView part = partitions.of(piece);
    const auto first = static_cast<std::uint64_t>(4 * tet + 1);
    EXPECT_EQ(values(part.node_tags), (std::vector<std::uint64_t>{first, first + 1, first + 2, first + 3}));
    EXPECT_EQ(part.tets.size, 5u);
    EXPECT_EQ(part.tets.data[0], boundary.size() + static_cast<std::uint64_t>(tet) + 1);
    ASSERT_EQ(part.triangles.size, 16u);
    for (std::size_t k = 0; k < 4; ++k)
      EXPECT_EQ(part.triangles.data[4 * k], static_cast<std::uint64_t>(4 * tet) + k + 1);
  }
}

// A boundary triangle that is no tet's face cannot be given a partition: an error, not a file
// that silently leaves it out.
TEST(MshPartitions, RefusesABoundaryTriangleThatIsNoTetsFace) {
  TwoTets m;
  m.boundary[1] = {0, 1, 4};
  EXPECT_THROW(MshPartitions(m.output(), false), InternalError);
}

// A spread mesh's partition: its tets in blocks (a bulk, the band's with their rows), its boundary
// triangles found from one block's tets and another's faces sent by their vertex sets. The arrays
// are those of the assembled mesh's partition.
TEST(MshBoundaryParts, BlocksAndFacesByVertexSetsGiveTheAssembledPartitions) {
  const TwoTets m;
  MshPartitions assembled(m.output(), /*binary=*/false);
  MshBoundaryParts boundary(m.boundary);
  const std::vector<Tet> first{m.mesh.tets[0]}, second{m.mesh.tets[1]};
  boundary.add_tets(first, {}, [](std::size_t) { return 0u; });  // no neighbours: every face
  std::vector<std::array<std::int32_t, 3>> faces;
  for (int j = 0; j < 4; ++j) {
    const FaceKey key(outward_face(second[0], j));
    faces.push_back({key.v[0], key.v[1], key.v[2]});
  }
  boundary.add_faces(faces, 1);
  boundary.group(2);
  const std::vector<std::int64_t> rows{1};
  MshPartHead head{2, 2, m.boundary.size(), 5, false, bounds_of(m.mesh.points)};
  const auto point = [&](std::int64_t id) { return m.mesh.points[id]; };
  for (int partition : {0, 1}) {
    head.partition = static_cast<std::uint64_t>(partition) + 1;
    const std::vector<Tet> none;
    const MshPartTets tets{1, [&](std::size_t) { return PointIds{}(partition == 0 ? first[0] : second[0]); },
                           [&](std::size_t) { return rows[0] - (partition == 0); }};
    const MshPartArrays part = msh_part_arrays(head, tets, boundary.rows(partition), point);
    const MshPartView expected = assembled.of(partition == 0 ? 0 : -1);
    EXPECT_EQ(part.about, values(expected.about)) << partition;
    EXPECT_EQ(part.node_tags, values(expected.node_tags)) << partition;
    EXPECT_EQ(part.triangles, values(expected.triangles)) << partition;
    EXPECT_EQ(part.tets, values(expected.tets)) << partition;
    EXPECT_EQ(part.xyz, std::vector<double>(expected.xyz.data, expected.xyz.data + expected.xyz.size)) << partition;
    EXPECT_EQ(part.box, std::vector<double>(expected.box.data, expected.box.data + 12)) << partition;
  }
}

// A boundary triangle that no block's face matches fails the grouping.
TEST(MshBoundaryParts, RefusesATriangleNoBlockHas) {
  const TwoTets m;
  MshBoundaryParts boundary(m.boundary);
  boundary.add_tets({m.mesh.tets[0]}, {}, [](std::size_t) { return 0u; });
  EXPECT_THROW(boundary.group(1), InternalError);
}

// The arrays as bytes and back; cut or missing arrays are refused, never written.
TEST(WritePieceFile, RefusesArraysThatDoNotFitTogether) {
  const TwoTets m;
  MshPartitions partitions(m.output(), false);
  const MshPartView part = partitions.of(0);
  PieceArrays arrays = arrays_of(part);
  ASSERT_TRUE(msh_part_from(arrays).has_value());
  EXPECT_EQ(values(msh_part_from(arrays)->tets), values(part.tets));
  const std::string dir = test::temp_dir("msh_test");
  const std::string path = dir + "/m_1.msh";
  PieceArrays cut = arrays;
  cut[5] = cut[5].substr(0, cut[5].size() - 1);
  EXPECT_FALSE(msh_part_from(cut).has_value());
  EXPECT_THROW(write_piece_file(MeshFormat::msh_parts, cut, path, "m_1.msh"), OutputError);
  cut = arrays;
  cut.pop_back();
  EXPECT_THROW(write_piece_file(MeshFormat::msh_parts, cut, path, "m_1.msh"), OutputError);
  // .vtu cells whose arrays disagree on the number of tets.
  const std::vector<double> xyz(12, 0.0);
  const std::vector<std::int64_t> connectivity{0, 1, 2, 3}, offsets{4, 8};
  const std::vector<std::uint8_t> types{10};
  const std::vector<std::int32_t> piece{0}, region{1};
  const std::vector<std::int64_t> global_ids{0, 1, 2, 3};
  const auto bytes = [](const auto& v) {
    return std::string_view(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(v[0]));
  };
  const PieceArrays cells{bytes(xyz),   bytes(connectivity), bytes(offsets),   bytes(types),
                          bytes(piece), bytes(region),       bytes(global_ids)};
  EXPECT_THROW(write_piece_file(MeshFormat::pvtu, cells, path, "m_p0.vtu"), OutputError);
  EXPECT_THROW(write_piece_file(MeshFormat::vtu, arrays, path, "m.vtu"), InternalError);
}

}  // namespace
}  // namespace partet
