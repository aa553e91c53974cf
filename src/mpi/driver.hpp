// The distributed job: rank 0 reads, partitions and closes; pieces are meshed on all ranks;
// rank 0 gathers, merges and writes. The driver only decides where pieces go and moves their
// bytes; every step ends with an agreement of all ranks.
#pragma once
#include <mpi.h>

#include <exception>
#include <string>

#include "job/compare_tetgen.hpp"
#include "job/job.hpp"

namespace partet::mpi {

struct JobStatus {
  int exit_code = 0;            // the same on every rank
  std::string error;            // on rank 0, when exit_code != 0
  bool meshing_failed = false;  // the error is a meshing failure another partition may help with
  bool split_faces_may_help = false;  // TetGen alone failed keeping every input triangle whole
  bool out_of_time = false;     // a piece, or the input as one piece, used its time limit
  bool usage_error = false;     // the command line asks for something impossible (exit code 2)
  RunFigures figures;           // rank 0, with MeshJob::compare_tetgen
  int ranks = 1;
};

// Call between MPI_Init and MPI_Finalize on every rank of MPI_COMM_WORLD.
JobStatus run_mesh_job(const MeshJob& job);

// The pipeline across the ranks of comm on a surface in memory (the library's collective call):
// every rank calls it; rank 0 meshes `input` (validated and scaled, see prepare_input; the other
// ranks' is ignored) and the others mesh the pieces it hands out. The result is on rank 0. An
// error is thrown on every rank: on rank 0 as it was, on the others with its type and message;
// failed_before (rank 0: e.g. the input was invalid) is thrown that way without meshing.
MeshResult mesh_collective(const SurfaceMesh& input, const MeshOptions& options, MPI_Comm comm,
                           StageTimes* times = nullptr, std::exception_ptr failed_before = nullptr);

// The MPI library's name and version ("Open MPI v4.1.4"); callable before MPI_Init.
std::string library_version();

}  // namespace partet::mpi
