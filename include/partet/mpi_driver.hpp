// The distributed job: rank 0 reads, partitions and closes; pieces are meshed on all ranks;
// rank 0 gathers, merges and writes. Every rank returns the same exit code.
#pragma once
#include <string>

#include "partet/pipeline.hpp"

namespace partet::mpi {

struct MeshJob {
  std::string input;
  std::string output_prefix;
  std::string report_path;  // empty: no JSON report
  MeshOptions options;
  bool check_output = false;  // run check_mesh on the result before writing
  bool quiet = false;
  std::string dump_pieces_dir;  // non-empty: write each piece's surface there before meshing it
};

// Call between MPI_Init and MPI_Finalize on every rank of MPI_COMM_WORLD.
int run_mesh_job(const MeshJob& job);

}  // namespace partet::mpi
