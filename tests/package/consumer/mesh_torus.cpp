// Meshes a generated torus through partet's API: in one process, or across the ranks of
// MPI_COMM_WORLD under mpirun; then an open surface, which must fail on every rank.
#include <partet/partet.hpp>

#include <cstdio>

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
