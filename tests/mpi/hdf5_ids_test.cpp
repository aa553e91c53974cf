// Parallel HDF5 under mpiexec -n 2: runs of tets in a block's compact 32-bit ids (a bulk's shift,
// the band's table) are written as the mesh's 64-bit ids past 2^31, each rank its own rows at
// once, and read back so by both ranks. Exits non-zero on any mismatch.
#include <mpi.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "io/parallel_hdf5.hpp"

int main(int argc, char** argv) {
  using namespace partet;
  MPI_Init(&argc, &argv);
  int rank = 0, size = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (size != 2) {
    if (rank == 0) std::fprintf(stderr, "run with mpiexec -n 2\n");
    MPI_Finalize();
    return 1;
  }
  // The directory, made by rank 0 and shared (one machine).
  char directory[] = "/tmp/partet_hdf5_ids_XXXXXX";
  if (rank == 0 && !mkdtemp(directory)) MPI_Abort(MPI_COMM_WORLD, 1);
  MPI_Bcast(directory, sizeof directory, MPI_CHAR, 0, MPI_COMM_WORLD);
  const Hdf5Paths paths{std::string(directory) + "/m.h5", std::string(directory) + "/m_boundary.h5", "m.h5",
                        "m_boundary.h5"};
  if (rank == 0) std::ofstream(paths.mesh), std::ofstream(paths.boundary);  // the writers' temporaries
  MPI_Barrier(MPI_COMM_WORLD);

  // Rank 0: a bulk whose own Steiner points (compact ids from 3) are the mesh's from 3 * 2^31;
  // rank 1: the band, its ids from 3 through a table past 2^32.
  const std::int64_t far = std::int64_t{3} << 31;
  const std::vector<std::int64_t> table{far + 7, (std::int64_t{1} << 32) + 5, std::int64_t{5} << 32};
  const std::vector<Tet> compact = rank == 0 ? std::vector<Tet>{{0, 1, 3, 4}, {2, 3, 4, 5}}
                                             : std::vector<Tet>{{0, 3, 4, 5}, {1, 2, 3, 5}};
  const PointIds ids = rank == 0 ? PointIds{3, far - 3, nullptr} : PointIds{3, 0, table.data()};
  const std::vector<std::int32_t> region{1, 2}, piece{rank, rank};
  const std::vector<Point3> points{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  MeshRowRuns runs;
  if (rank == 0) runs.points.push_back({0, {points.data(), points.size()}});
  runs.tets.push_back({static_cast<std::uint64_t>(2 * rank), {compact.data(), compact.size()},
                       {region.data(), region.size()}, {piece.data(), piece.size()}, ids});
  const MeshTotals totals{points.size(), 4, 0};
  int failures = 0;
  try {
    write_mesh_runs_hdf5(MPI_COMM_WORLD, runs, totals, paths);
    MeshTotals read;
    const MeshBlock block = read_mesh_hdf5(MPI_COMM_WORLD, paths.mesh, paths.boundary, read);
    // Each rank reads back half the rows: rank r rows [2r, 2r + 2), the rows it wrote.
    for (std::size_t t = 0; t < compact.size(); ++t) {
      const GlobalTet expected = ids(compact[t]);
      if (t >= block.tets.size() || block.tets[t] != expected) {
        std::fprintf(stderr, "rank %d: tet %zu read back differs\n", rank, t);
        ++failures;
      }
    }
    if (read.tets != 4 || read.points != 4) ++failures;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rank %d: %s\n", rank, e.what());
    ++failures;
  }
  int all = 0;
  MPI_Allreduce(&failures, &all, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  if (rank == 0) {
    std::remove(paths.mesh.c_str()), std::remove(paths.boundary.c_str()), std::remove(directory);
    std::printf(all == 0 ? "ok: tets past 2^31 points written from compact ids and read back on 2 ranks\n"
                         : "FAIL: %d mismatches\n",
                all);
  }
  MPI_Finalize();
  return all == 0 ? 0 : 1;
}
