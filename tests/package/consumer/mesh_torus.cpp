// Meshes a generated torus through partet's API: in one process, or across the ranks of
// MPI_COMM_WORLD under mpirun; again with a scratch directory (the same tets, the directory empty
// after); then an open surface and a missing scratch directory, which must fail on every rank.
#include <partet/partet.hpp>

#include <dirent.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

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
  char scratch[] = "/tmp/partet_consumer_XXXXXX";
  if (rank == 0 && !mkdtemp(scratch)) MPI_Abort(MPI_COMM_WORLD, 1);
  MPI_Bcast(scratch, sizeof scratch, MPI_CHAR, 0, MPI_COMM_WORLD);
  partet::Options on_disk = options;
  on_disk.scratch = scratch;
  const partet::Result spilled = mesh(torus, on_disk, size);
  if (rank == 0) {
    const bool same = spilled.mesh.tets == result.mesh.tets && spilled.mesh.points == result.mesh.points;
    std::printf("with a scratch directory: %s, %d files left\n", same ? "the same tets" : "OTHER TETS", entries(scratch));
    failed = failed || !same || entries(scratch) != 0;
    rmdir(scratch);
  }
  on_disk.scratch = std::string(scratch) + "/missing";
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
