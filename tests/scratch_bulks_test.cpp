// Scratch bulks (the paper's memory mode): a bulk comes back from its file as it was put, the files
// go once taken or when the store ends, a lost or changed file is an error naming it, a directory
// that cannot be written keeps the bulks in memory; and a welder whose bulks waited on disk gives
// the mesh, and the pieces taken back, that it gives keeping them in memory.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "io/scratch_bulks.hpp"
#include "job/pipeline.hpp"
#include "partet/errors.hpp"
#include "stage_batches.hpp"
#include "stages/generate.hpp"
#include "stages/merge.hpp"
#include "test_support.hpp"

namespace partet {
namespace {

using namespace partet::test;
namespace fs = std::filesystem;

std::size_t files_in(const std::string& directory) {
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(directory), fs::directory_iterator()));
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

TEST(ScratchBulks, ABulkComesBackAsItWasPutAndItsFileGoes) {
  const std::string dir = temp_dir("scratch_round_trip");
  ScratchBulks store(dir);
  ASSERT_TRUE(store.put(0, some_block(0)));
  ASSERT_TRUE(store.put(7, some_block(3)));
  ASSERT_TRUE(store.put(7, some_block(4)));  // put again (a piece split again): the new one counts
  EXPECT_EQ(files_in(dir), 2u);
  expect_same_block(store.take(7), some_block(4));
  EXPECT_EQ(files_in(dir), 1u);
  expect_same_block(store.take(0), some_block(0));
  EXPECT_EQ(files_in(dir), 0u);
  EXPECT_EQ(store.stats().bulks, 2);
  EXPECT_THROW(store.take(0), Error);  // taken once
}

TEST(ScratchBulks, TheFilesGoWhenTheStoreEnds) {
  const std::string dir = temp_dir("scratch_end");
  {
    ScratchBulks store(dir);
    ASSERT_TRUE(store.put(1, some_block(1)));
    ASSERT_TRUE(store.put(2, some_block(2)));
    EXPECT_EQ(files_in(dir), 2u);
  }
  EXPECT_EQ(files_in(dir), 0u);
}

TEST(ScratchBulks, ALostOrChangedFileIsAnErrorNamingIt) {
  const std::string dir = temp_dir("scratch_lost");
  ScratchBulks store(dir);
  ASSERT_TRUE(store.put(0, some_block(0)));
  ASSERT_TRUE(store.put(1, some_block(1)));
  std::vector<std::string> paths;
  for (const auto& entry : fs::directory_iterator(dir)) paths.push_back(entry.path().string());
  ASSERT_EQ(paths.size(), 2u);
  fs::remove(paths[0]);
  fs::resize_file(paths[1], fs::file_size(paths[1]) - 8);
  for (int piece : {0, 1}) {
    try {
      store.take(piece);
      ADD_FAILURE() << "piece " << piece << ": no error";
    } catch (const Error& e) {
      EXPECT_TRUE(contains(e.what(), "scratch file '" + dir));
      EXPECT_TRUE(contains(e.what(), "piece " + std::to_string(piece)));
    }
  }
  EXPECT_EQ(files_in(dir), 0u);
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
      const std::int32_t first_removed = split.input_vertex_count;
      const BandSpec spec{split.input_vertex_count, static_cast<std::int32_t>(split.points.size()), first_removed,
                          first_removed + static_cast<std::int32_t>(split.cut_vertex_count()), layers};
      const std::string dir = temp_dir("scratch_welder");
      ScratchBulks store(dir);
      Welder in_memory(split, s.prepared.pieces), on_disk(split, s.prepared.pieces);
      in_memory.split_on_arrival(spec), on_disk.split_on_arrival(spec);
      on_disk.keep_bulks_in(store);
      for (const auto& result : s.results) in_memory.add(PieceTetMesh(result)), on_disk.add(PieceTetMesh(result));
      TetMesh a = in_memory.finish_band(split.points, spec), b = on_disk.finish_band(split.points, spec);
      EXPECT_EQ(store.stats().bulks, k);
      EXPECT_EQ(files_in(dir), static_cast<std::size_t>(k));
      expect_same_tet_mesh(b, a);
      EXPECT_EQ(on_disk.bulk_tet_count(), in_memory.bulk_tet_count());
      expect_same_tet_mesh(on_disk.assemble(std::move(b)), in_memory.assemble(std::move(a)));
      EXPECT_EQ(files_in(dir), 0u);
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
  welder.split_on_arrival(BandSpec{split.input_vertex_count, static_cast<std::int32_t>(split.points.size()),
                                   split.input_vertex_count,
                                   split.input_vertex_count + static_cast<std::int32_t>(split.cut_vertex_count()), 1});
  welder.keep_bulks_in(store);
  for (const auto& result : s.results) welder.add(PieceTetMesh(result));
  EXPECT_EQ(files_in(dir), s.results.size());
  expect_pieces_come_back(welder, s.results);
  EXPECT_EQ(files_in(dir), 0u);
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
  }
}

}  // namespace
}  // namespace partet
