// Rank 0's side of the meshing (internal header): the scheduler that hands the pieces, seam
// regions and caps to the ranks as they become free, meshes pieces itself between looks at MPI,
// and keeps track of which rank keeps which piece's bulk.
#pragma once
#include <cstddef>
#include <map>
#include <memory>
#include <optional>

#include "job/job.hpp"
#include "job/pipeline.hpp"

namespace partet::mpi {

// The scheduler of a job on `size` ranks (the workers run worker_loop). With input_verdict_faces,
// the other ranks are checking the input of that many faces (check_input_on_rank), and the
// scheduler's confirm_input waits for rank 1's verdict. records: where each piece was meshed.
std::unique_ptr<PieceScheduler> root_scheduler(const MeshJob& job, int size, RankStats& stats,
                                               std::map<int, PieceRecord>& records, double job_start,
                                               std::optional<std::size_t> input_verdict_faces = std::nullopt);

}  // namespace partet::mpi
