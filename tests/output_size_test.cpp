// The least room a mesh's files take (io/output_size.hpp): a lower bound, so no run it stops could
// have written its files. A real mesh written in every format takes at least what the bound says
// from its exact counts, and has at least the counts bounded from its input alone; the binary
// formats' bound is their arrays' size, close to the files'.
#include "io/output_size.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include "io/output_set.hpp"
#include "job/pipeline.hpp"
#include "stages/generate.hpp"
#include "test_support.hpp"

namespace partet {
namespace {

std::uintmax_t bytes_in(const std::string& directory) {
  std::uintmax_t total = 0;
  for (const auto& entry : std::filesystem::directory_iterator(directory)) total += entry.file_size();
  return total;
}

TEST(OutputSize, NoFormatWritesAMeshInLessThanItsBound) {
  const SurfaceMesh input = generate_surface("genus3", 20000);
  MeshOptions options;
  options.pieces = 3;
  const MeshResult result = mesh_surface(input, options);
  const MeshCounts exact{static_cast<std::int64_t>(result.mesh.points.size()),
                         static_cast<std::int64_t>(result.mesh.tets.size()),
                         static_cast<std::int64_t>(input.triangles.size())};
  const MeshCounts least = least_mesh_counts(static_cast<std::int64_t>(input.points.size()), exact.faces);
  EXPECT_LE(least.points, exact.points);
  EXPECT_LE(least.tets, exact.tets);
  EXPECT_EQ(least.tets, (exact.faces + 3) / 4);

  const MeshOutput output{result.mesh, input.triangles};
  // (The formats other ranks help write, .pvtu, XDMF and the MSH partitions, in every run's
  // place: tests/cli/disk_space.sh.)
  for (const char* name : {"tetgen", "vtu", "msh", "msh-binary", "medit"}) {
    const MeshFormat format = mesh_format(name);
    const std::string directory = test::temp_dir(std::string("output_size_") + name);
    OutputSet set(journal_path(directory + "/m"));
    add_mesh_files(set, format, output, directory + "/m", RankWriters{});
    set.publish();
    std::filesystem::remove(journal_path(directory + "/m"));
    const std::uintmax_t written = bytes_in(directory);
    const std::uint64_t bound = least_output_bytes({format}, exact);
    EXPECT_LE(bound, written) << name;
    EXPECT_LE(least_output_bytes({format}, least), bound) << name;
    if (format == MeshFormat::msh_binary)
      EXPECT_GT(static_cast<double>(bound), 0.95 * static_cast<double>(written)) << name;
    else if (format != MeshFormat::vtu)
      EXPECT_GT(static_cast<double>(bound), 0.2 * static_cast<double>(written)) << name;
  }
  EXPECT_EQ(least_output_bytes({MeshFormat::tetgen, MeshFormat::xdmf}, exact),
            least_output_bytes({MeshFormat::tetgen}, exact) + least_output_bytes({MeshFormat::xdmf}, exact));
}

TEST(OutputSize, TextRowsCountEveryDigitOfTheirNumbers) {
  // 12 points and 3 tets as TetGen's files: .node rows 0..11 (10 + 2*2 digits) and 7 characters
  // each; .ele rows 0..2 (3 digits), ids 0..11 once (14 digits), and 5 characters each; .face
  // rows 0..19 (10 + 10*2 digits), 9 characters each; .neigh 3 digits and 9 characters each.
  const MeshCounts c{12, 3, 20};
  EXPECT_EQ(least_output_bytes({MeshFormat::tetgen}, c), (14 + 84) + (3 + 14 + 15) + (30 + 180) + (3 + 27));
  EXPECT_EQ(least_output_bytes({MeshFormat::vtu, MeshFormat::pvtu}, c), 0u);  // compressed
  EXPECT_EQ(least_output_bytes({MeshFormat::msh_binary}, c), 32u * 12 + 32u * 20 + 40u * 3);
}

TEST(OutputSize, TheLeastMeshOfASurface) {
  EXPECT_EQ(least_mesh_counts(4, 4).tets, 1);  // one tet
  EXPECT_EQ(least_mesh_counts(8, 8).tets, 2);  // two shells of one tet each
  EXPECT_EQ(least_mesh_counts(1000, 1996).tets, 499);
  EXPECT_EQ(least_mesh_counts(1000, 1996).points, 1000);
}

}  // namespace
}  // namespace partet
