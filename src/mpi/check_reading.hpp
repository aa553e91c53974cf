// The check on several ranks (distributed_check.hpp), internal: what each rank reads of the input
// and of the mesh's files, into its Part.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "mpi/check_exchange.hpp"
#include "partet/mesh_types.hpp"

namespace partet::distributed {

// What the check needs of the input, on every rank; the surface itself stays on rank 0.
struct InputFigures {
  SurfaceMesh read;                // rank 0's, read from the file
  const SurfaceMesh* held = nullptr;  // rank 0's, when the run holds the input already
  long double volume = 0, euler = 0;
  const SurfaceMesh& surface() const { return held ? *held : read; }
};
// Collective: rank 0 reads the input, every rank gets its figures.
InputFigures read_input(MPI_Comm comm, int rank, const std::string& path);
// Collective: the figures of the input rank 0 holds (`held`, null on the other ranks), which
// must outlive them.
InputFigures held_input(MPI_Comm comm, int rank, const SurfaceMesh* held);

// Collective: this rank's part of a set mesh_read.hpp reads (see check_mesh_file_set).
void read_mesh_part(Part& part, const std::string& path);

// What only a TetGen set has besides the mesh: its .neigh rows (tet id order, this rank's run),
// and a violation when its files carry different set IDs.
struct TetgenExtras {
  std::vector<std::array<Id, 4>> neighbours;
  std::string set_violation;
};
// Collective: this rank's part of the TetGen files at prefix (see check_tetgen_set), each file
// read under its name followed by `suffix` (a run's temporaries).
TetgenExtras read_tetgen_parts(Part& part, const std::string& prefix, const std::string& suffix = "");

}  // namespace partet::distributed
