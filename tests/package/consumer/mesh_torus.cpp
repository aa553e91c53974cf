// Meshes a generated torus through partet's API: in one process, or across the ranks of
// MPI_COMM_WORLD under mpirun; again with a scratch directory (the same tets, the directory empty
// after); twice with a checkpoint directory (the second call takes every piece); then an open
// surface and a missing scratch directory, which must fail on every rank.
#include <partet/partet.hpp>

#include <dirent.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

partet::Result mesh(const partet::SurfaceMesh& surface, const partet::Options& options, int size) {
  return size == 1 ? partet::tetrahedralize(surface, options) : partet::tetrahedralize(surface, options, MPI_COMM_WORLD);
}

int entries(const std::string& directory) {
  int n = 0;
  if (DIR* dir = opendir(directory.c_str())) {
    while (const dirent* entry = readdir(dir)) n += entry->d_name[0] != '.';
    closedir(dir);
  }
  return n;
}

// A new empty directory every rank knows (made by rank 0).
std::string new_directory(int rank) {
  char path[] = "/tmp/partet_consumer_XXXXXX";
  if (rank == 0 && !mkdtemp(path)) MPI_Abort(MPI_COMM_WORLD, 1);
  MPI_Bcast(path, sizeof path, MPI_CHAR, 0, MPI_COMM_WORLD);
  return path;
}

// "name inode" of every file in a directory, sorted.
std::vector<std::string> file_inodes(const std::string& directory) {
  std::vector<std::string> files;
  if (DIR* dir = opendir(directory.c_str())) {
    while (const dirent* entry = readdir(dir))
      if (entry->d_name[0] != '.') files.push_back(std::string(entry->d_name) + " " + std::to_string(entry->d_ino));
    closedir(dir);
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const partet::SurfaceMesh torus = partet::generate_surface("torus", 2000);
  partet::Options options;
  options.pieces = 4;
  const partet::Result result = size == 1 ? partet::tetrahedralize(torus, options)
                                          : partet::tetrahedralize(torus, options, MPI_COMM_WORLD);
  int failed = 0;
  if (rank == 0) {
    const std::vector<std::string> problems = partet::check(torus, result);
    std::printf("partet %s, %d rank(s): %zu tets in %d pieces, %s\n", partet::version().c_str(), size,
                result.mesh.tets.size(), result.report.pieces, problems.empty() ? "check passed" : problems[0].c_str());
    failed = !problems.empty() || result.mesh.tets.empty();
  }
  const std::string scratch = new_directory(rank);
  partet::Options on_disk = options;
  on_disk.scratch = scratch;
  const partet::Result spilled = mesh(torus, on_disk, size);
  if (rank == 0) {
    const bool same = spilled.mesh.tets == result.mesh.tets && spilled.mesh.points == result.mesh.points;
    std::printf("with a scratch directory: %s, %d files left\n", same ? "the same tets" : "OTHER TETS", entries(scratch));
    failed = failed || !same || entries(scratch) != 0;
    rmdir(scratch.c_str());
  }
  // With a checkpoint: every piece kept; a second call takes them all (their files are not
  // written again: the same inodes), and both give the same tets.
  const std::string kept = new_directory(rank);
  partet::Options checkpointed = options;
  checkpointed.checkpoint = kept;
  const partet::Result first = mesh(torus, checkpointed, size);
  const std::vector<std::string> inodes = file_inodes(kept);
  const partet::Result again = mesh(torus, checkpointed, size);
  if (rank == 0) {
    const bool same = first.mesh.tets == result.mesh.tets && again.mesh.tets == result.mesh.tets &&
                      again.mesh.points == result.mesh.points;
    const bool taken = inodes.size() == static_cast<std::size_t>(options.pieces) && file_inodes(kept) == inodes;
    std::printf("with a checkpoint: %s, %zu pieces kept, %s\n", same ? "the same tets" : "OTHER TETS", inodes.size(),
                taken ? "all taken by the second call" : "NOT TAKEN");
    failed = failed || !same || !taken;
    for (const std::string& entry : inodes) unlink((kept + "/" + entry.substr(0, entry.find(' '))).c_str());
    rmdir(kept.c_str());
  }
  on_disk.scratch = scratch + "/missing";
  try {
    mesh(torus, on_disk, size);
    std::printf("rank %d: a missing scratch directory was accepted\n", rank);
    failed = 1;
  } catch (const partet::OptionError& e) {
    std::printf("rank %d: missing scratch directory refused: %s\n", rank, e.what());
  }
  partet::SurfaceMesh open = torus;
  open.triangles.pop_back();
  try {
    size == 1 ? partet::tetrahedralize(open, options) : partet::tetrahedralize(open, options, MPI_COMM_WORLD);
    std::printf("rank %d: an open surface was meshed\n", rank);
    failed = 1;
  } catch (const partet::InputError& e) {
    std::printf("rank %d: open surface refused: %s\n", rank, e.what());
  }
  MPI_Finalize();
  return failed;
}
