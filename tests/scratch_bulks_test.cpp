// Scratch bulks (the paper's memory mode): a bulk comes back from the store's file as it was put;
// that file has no name in the directory and gives a bulk's space back once taken; a bulk that
// cannot be read back is an error naming it; a dead run's files are removed; a directory that
// cannot be written keeps the bulks in memory; and a welder whose bulks waited on disk gives the
// mesh, and the pieces taken back, that it gives keeping them in memory.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "io/file_owner.hpp"
#include "io/scratch_bulks.hpp"
#include "job/pipeline.hpp"
#include "partet/errors.hpp"
#include "stage_batches.hpp"
#include "stages/generate.hpp"
#include "stages/merge.hpp"
#include "stages/seam_healing.hpp"
#include "stages/spread_mesh.hpp"
#include "test_support.hpp"

namespace partet {
namespace {

using namespace partet::test;
namespace fs = std::filesystem;

std::size_t files_in(const std::string& directory) {
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(directory), fs::directory_iterator()));
}

// The band around the cut vertices alone (healing without the caps' points), `layers` deep.
BandSpec cut_vertices_band(const SplitSurface& split, int layers) {
  const std::int32_t first_removed = split.input_vertex_count;
  return {split.input_vertex_count, static_cast<std::int32_t>(split.points.size()), first_removed,
          first_removed + static_cast<std::int32_t>(split.cut_vertex_count()), layers};
}

// Two welders of the same pieces split on arrival: one keeps the bulks in memory, the other in
// `store`; every piece added to both.
void add_to_both(Welder& in_memory, Welder& on_disk, BulkStore& store, const MeshedPieces& s, const BandSpec& spec) {
  in_memory.split_on_arrival(spec), on_disk.split_on_arrival(spec);
  on_disk.keep_bulks_in(store);
  for (const auto& result : s.results) in_memory.add(PieceTetMesh(result)), on_disk.add(PieceTetMesh(result));
}

// This process's open files in directory (a nameless file shows as "DIR/#inode (deleted)").
std::vector<int> descriptors_into(const std::string& directory) {
  std::vector<int> found;
  for (const auto& entry : fs::directory_iterator("/proc/self/fd")) {
    std::error_code error;
    const std::string target = fs::read_symlink(entry.path(), error).string();
    if (!error && target.rfind(fs::canonical(directory).string() + "/", 0) == 0)
      found.push_back(std::stoi(entry.path().filename().string()));
  }
  return found;
}

// Disk blocks the open file fd holds.
long long blocks_of(int fd) {
  struct stat info {};
  return ::fstat(fd, &info) == 0 ? static_cast<long long>(info.st_blocks) : -1;
}

TetBlock some_block(int seed) {
  TetBlock block;
  block.in = true;
  for (int i = 0; i < 5 + seed; ++i) {
    block.steiner_points.push_back({0.5 * i, -1.0 * seed, 1e-300 * i});
    block.tets.push_back({i, i + 1, i + 2, i + 3 + seed});
    block.neighbours.push_back({-1, i - 1, i + 1, seed});
  }
  block.rim = {3, 17, std::uint64_t{1} << 40};
  return block;
}

void expect_same_block(const TetBlock& a, const TetBlock& b) {
  EXPECT_EQ(a.steiner_points, b.steiner_points);
  EXPECT_EQ(a.tets, b.tets);
  EXPECT_EQ(a.neighbours, b.neighbours);
  EXPECT_EQ(a.rim, b.rim);
}

TEST(ScratchBulks, ABulkComesBackAsItWasPut) {
  const std::string dir = temp_dir("scratch_round_trip");
  ScratchBulks store(dir);
  ASSERT_TRUE(store.put(0, some_block(0)));
  ASSERT_TRUE(store.put(7, some_block(3)));
  ASSERT_TRUE(store.put(7, some_block(4)));  // put again (a piece split again): the new one counts
  expect_same_block(store.take(7), some_block(4));
  expect_same_block(store.take(0), some_block(0));
  EXPECT_EQ(store.stats().bulks, 2);
  EXPECT_FALSE(store.holds(0));
  EXPECT_THROW(store.take(0), Error);  // taken once
}

// The bulks wait in a file without a name in the directory (nothing a kill could leave there),
// which the store holds open; a bulk taken back, or dropped, gives its disk space back; the file
// goes with the store.
TEST(ScratchBulks, TheBulksWaitInOneFileWithoutANameThatGoesWithTheStore) {
  const std::string dir = temp_dir("scratch_nameless");
  {
    ScratchBulks store(dir);
    TetBlock large = some_block(1);
    large.tets.resize(200000, Tet{1, 2, 3, 4});
    large.neighbours.resize(200000, Tet{-1, -1, -1, -1});
    ASSERT_TRUE(store.put(1, large));
    ASSERT_TRUE(store.put(2, large));
    ASSERT_TRUE(store.put(3, some_block(3)));
    EXPECT_EQ(files_in(dir), 0u);
    const std::vector<int> open = descriptors_into(dir);
    ASSERT_EQ(open.size(), 1u);
    const long long both = blocks_of(open[0]);
    EXPECT_GE(both * 512, 2 * 200000 * 2 * static_cast<long long>(sizeof(Tet)));
    expect_same_block(store.take(1), large);
    store.drop(2);
    EXPECT_FALSE(store.holds(2));
    EXPECT_LT(blocks_of(open[0]) * 4, both);  // (a hole punched, or the file cut)
    expect_same_block(store.take(3), some_block(3));
    EXPECT_EQ(blocks_of(open[0]), 0);
  }
  EXPECT_TRUE(descriptors_into(dir).empty());
  EXPECT_EQ(files_in(dir), 0u);
}

// Where the filesystem has no nameless files (NFS), the file is named and unlinked at once: the
// same, nothing in the directory, the bulks back as they were put.
TEST(ScratchBulks, WithoutNamelessFilesTheFileLosesItsNameAtOnce) {
  const std::string dir = temp_dir("scratch_named");
  ::setenv("PARTET_TEST_NO_NAMELESS_FILES", "1", 1);
  {
    ScratchBulks store(dir);
    ASSERT_TRUE(store.put(4, some_block(4)));
    ASSERT_TRUE(store.put(5, some_block(5)));
    EXPECT_EQ(files_in(dir), 0u);
    const std::vector<int> open = descriptors_into(dir);
    ASSERT_EQ(open.size(), 1u);
    EXPECT_TRUE(contains(fs::read_symlink("/proc/self/fd/" + std::to_string(open[0])).string(), "partet-bulk-store"));
    expect_same_block(store.take(5), some_block(5));
    expect_same_block(store.take(4), some_block(4));
  }
  ::unsetenv("PARTET_TEST_NO_NAMELESS_FILES");
  EXPECT_TRUE(descriptors_into(dir).empty());
  EXPECT_EQ(files_in(dir), 0u);
}

// The file cut short under the store (a failing disk, something writing through /proc): taking a
// bulk back is an error naming the piece and the directory.
TEST(ScratchBulks, ABulkThatCannotBeReadBackIsAnErrorNamingIt) {
  const std::string dir = temp_dir("scratch_lost");
  ScratchBulks store(dir);
  ASSERT_TRUE(store.put(0, some_block(0)));
  ASSERT_TRUE(store.put(1, some_block(1)));
  const std::vector<int> open = descriptors_into(dir);
  ASSERT_EQ(open.size(), 1u);
  struct stat info {};
  ASSERT_EQ(::fstat(open[0], &info), 0);
  ASSERT_EQ(::ftruncate(open[0], info.st_size - 8), 0);
  expect_same_block(store.take(0), some_block(0));
  try {
    store.take(1);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_TRUE(contains(e.what(), "scratch file in '" + dir + "'")) << e.what();
    EXPECT_TRUE(contains(e.what(), "piece 1")) << e.what();
  }
}

// The scratch files a killed run left (on a filesystem without nameless files, or an earlier
// partet's) go when their process is gone; a running process's, and another host's, stay.
TEST(ScratchBulks, ADeadRunsFilesAreRemoved) {
  const std::string dir = temp_dir("scratch_stale");
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  ASSERT_EQ(::waitpid(child, nullptr, 0), child);
  const std::string other_host = host_tag() == "00000000" ? "00000001" : "00000000";
  const std::string dead = dir + "/partet-bulk-store.tmp-" + std::to_string(child) + "-" + host_tag() + "-0000abcd";
  const std::string living =
      dir + "/partet-bulk-store.tmp-" + std::to_string(::getpid()) + "-" + host_tag() + "-0000abcd";
  const std::string elsewhere = dir + "/partet-bulk-3-0.tmp-" + std::to_string(child) + "-" + other_host + "-0000abcd";
  const std::string not_ours = dir + "/notes.tmp-" + std::to_string(child) + "-" + host_tag() + "-0000abcd";
  for (const std::string& path : {dead, living, elsewhere, not_ours}) std::ofstream(path) << "x";
  remove_stale_scratch(dir);
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_TRUE(fs::exists(living));
  EXPECT_TRUE(fs::exists(elsewhere));
  EXPECT_TRUE(fs::exists(not_ours));
}

TEST(ScratchBulks, ADirectoryThatCannotBeWrittenKeepsTheBulksInMemory) {
  ScratchBulks store(temp_dir("scratch_gone") + "/missing");
  EXPECT_FALSE(store.put(0, some_block(0)));
  EXPECT_EQ(store.stats().bulks, 0);
  EXPECT_THROW(check_scratch_directory(temp_dir("scratch_gone") + "/missing"), OptionError);
  EXPECT_NO_THROW(check_scratch_directory(temp_dir("scratch_fine")));
}

// Every bulk waits on disk from its split to the assembly: the same band, the same assembled
// mesh; one layer (split on arrival, thin pieces at 12) and two (split at the end).
TEST(ScratchBulks, AWelderWhoseBulksWaitedOnDiskGivesTheSameMesh) {
  for (const int k : {3, 12})
    for (const int layers : {1, 2}) {
      SCOPED_TRACE("k=" + std::to_string(k) + " layers=" + std::to_string(layers));
      const SurfaceMesh input = generate_surface("torus", 1500);
      const MeshedPieces s = mesh_pieces_in_batch(input, k);
      const SplitSurface& split = s.prepared.split;
      const BandSpec spec = cut_vertices_band(split, layers);
      const std::string dir = temp_dir("scratch_welder");
      ScratchBulks store(dir);
      Welder in_memory(split, s.prepared.pieces), on_disk(split, s.prepared.pieces);
      add_to_both(in_memory, on_disk, store, s, spec);
      TetMesh a = in_memory.finish_band(split.points, spec), b = on_disk.finish_band(split.points, spec);
      EXPECT_EQ(store.stats().bulks, k);
      for (int piece = 0; piece < k; ++piece) EXPECT_TRUE(store.holds(piece));
      expect_same_tet_mesh(b, a);
      EXPECT_EQ(on_disk.bulk_tet_count(), in_memory.bulk_tet_count());
      expect_same_tet_mesh(on_disk.assemble(std::move(b)), in_memory.assemble(std::move(a)));
      for (int piece = 0; piece < k; ++piece) EXPECT_FALSE(store.holds(piece));
      EXPECT_EQ(files_in(dir), 0u);
    }
}

// A mesh left spread (several ranks, --scratch): this process's bulks come back from its scratch
// file and are its own, here, as those it kept in memory; the welder keeps nothing elsewhere, and
// the file is empty after.
TEST(ScratchBulks, AMeshLeftSpreadTakesItsBulksBackFromDisk) {
  for (const char* name : {"torus", "nested"}) {
    SCOPED_TRACE(name);
    const SurfaceMesh input = generate_surface(name, 1500);
    const MeshedPieces s = mesh_pieces_in_batch(input, 4);
    const SplitSurface& split = s.prepared.split;
    const BandSpec spec = cut_vertices_band(split, 1);
    const std::string dir = temp_dir("scratch_spread");
    ScratchBulks store(dir);
    Welder in_memory(split, s.prepared.pieces), on_disk(split, s.prepared.pieces);
    add_to_both(in_memory, on_disk, store, s, spec);
    EXPECT_FALSE(on_disk.keeps_bulks_elsewhere());  // its own file is not another rank
    TetMesh a = in_memory.finish_band(split.points, spec), b = on_disk.finish_band(split.points, spec);
    const HealOptions heal{false, 0, false};
    heal_seams(a, input, split, heal, regions_here(s.options));
    heal_seams(b, input, split, heal, regions_here(s.options));
    EXPECT_EQ(store.stats().bulks, 4);
    const SpreadMesh want = in_memory.spread(std::move(a)), got = on_disk.spread(std::move(b));
    EXPECT_TRUE(store.pieces().empty());
    EXPECT_EQ(files_in(dir), 0u);
    ASSERT_EQ(got.bulks.size(), want.bulks.size());
    EXPECT_EQ(got.points, want.points);
    EXPECT_EQ(got.tets, want.tets);
    EXPECT_EQ(got.split_points, want.split_points);
    EXPECT_EQ(got.band_tets, want.band_tets);
    EXPECT_EQ(got.band_solid, want.band_solid);
    for (std::size_t p = 0; p < want.bulks.size(); ++p) {
      SCOPED_TRACE("piece " + std::to_string(p));
      const SpreadBulk &g = got.bulks[p], &w = want.bulks[p];
      EXPECT_TRUE(g.here);
      EXPECT_EQ(g.first_point, w.first_point);
      EXPECT_EQ(g.first_tet, w.first_tet);
      EXPECT_EQ(g.block.tets, w.block.tets);
      EXPECT_EQ(g.block.neighbours, w.block.neighbours);
      EXPECT_EQ(g.block.steiner_points, w.block.steiner_points);
      EXPECT_EQ(g.solid, w.solid);
      ASSERT_EQ(g.across.size(), w.across.size());
      for (std::size_t i = 0; i < w.across.size(); ++i)
        EXPECT_TRUE(g.across[i].face == w.across[i].face && g.across[i].tet == w.across[i].tet);
    }
  }
}

// A retry keeps the pieces that did not fail: a piece whose bulk waited on disk comes back as added.
TEST(ScratchBulks, APieceWhoseBulkWaitedOnDiskComesBackAsItWasAdded) {
  const SurfaceMesh input = generate_surface("genus3", 1500);
  const MeshedPieces s = mesh_pieces_in_batch(input, 4);
  const SplitSurface& split = s.prepared.split;
  const std::string dir = temp_dir("scratch_take_back");
  ScratchBulks store(dir);
  Welder welder(split, s.prepared.pieces);
  welder.split_on_arrival(cut_vertices_band(split, 1));
  welder.keep_bulks_in(store);
  for (const auto& result : s.results) welder.add(PieceTetMesh(result));
  for (std::size_t piece = 0; piece < s.results.size(); ++piece) EXPECT_TRUE(store.holds(static_cast<int>(piece)));
  expect_pieces_come_back(welder, s.results);
  for (std::size_t piece = 0; piece < s.results.size(); ++piece) EXPECT_FALSE(store.holds(static_cast<int>(piece)));
}

// The pipeline's weld and heal with --scratch: the same result, with and without a quality bound
// (which heals the caps too, and splits the pieces at the end), and nothing left in the directory.
TEST(ScratchBulks, ThePipelineWithScratchGivesTheSameResult) {
  for (const std::string quality : {"", "1.414"}) {
    SCOPED_TRACE("quality '" + quality + "'");
    const SurfaceMesh input = generate_surface("nested", 1500);
    const MeshedPieces s = mesh_pieces_in_batch(input, 4, 0.25, quality);
    MeshOptions with_scratch = s.options;
    with_scratch.scratch = temp_dir("scratch_pipeline");
    const MeshResult a = finish_mesh(input, s.prepared, std::vector<PieceTetMesh>(s.results), s.options);
    const MeshResult b = finish_mesh(input, s.prepared, std::vector<PieceTetMesh>(s.results), with_scratch);
    expect_same_tet_mesh(b.mesh, a.mesh);
    EXPECT_EQ(b.scratch_bulks, 4);
    EXPECT_GT(b.scratch_bytes, 0);
    EXPECT_EQ(a.scratch_bulks, 0);
    EXPECT_EQ(files_in(with_scratch.scratch), 0u);
    EXPECT_TRUE(descriptors_into(with_scratch.scratch).empty());
  }
}

}  // namespace
}  // namespace partet
