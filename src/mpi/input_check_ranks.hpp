// With several ranks, the others check the input while rank 0 partitions it, each its share
// (input_share.hpp): rank 0 broadcasts each vertex's share, the faces and the points in parts;
// each rank keeps its share and checks it; ranks 2... send their findings to rank 1 ("F" + the
// findings' bytes, or "E" + an error), which merges them in rank order and sends rank 0 the
// verdict: "" (valid), "I" + an InputError's message, or "E" + another error's (internal
// header).
#pragma once
#include <cstddef>

#include "job/job.hpp"
#include "partet/mesh_types.hpp"

namespace partet::mpi {

// How long rank 1 waits for the other checking ranks' findings on an input of `faces` faces:
// kWorkerSeconds + 1 s per million faces (rank 0 waits as long for rank 1's verdict on 2 ranks,
// twice as long on more).
double input_check_limit(std::size_t faces);

// Rank 0: sends the input to the checking ranks (every rank but 0).
void send_input_for_checks(const SurfaceMesh& input, int size);
// A rank other than 0: checks its share; rank 1 also merges the others' findings and sends rank
// 0 the verdict.
void check_input_on_rank(int rank, int size, RankStats& stats);

}  // namespace partet::mpi
