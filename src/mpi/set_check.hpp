// --check of a mesh left where its parts are (internal header): once the files are written under
// temporary names, rank 0 orders every rank to read them back and check them, as `partet check`
// under mpirun does (distributed_check.hpp), before they are published. So no rank assembles the
// mesh to check it. The order, broadcast among the writes' (rank_writes.hpp): "check", then the
// format's name, the absolute prefix and the temporaries' suffix, a line each; then the cut
// planes as bytes. Every rank then takes part in the check's collectives.
#pragma once
#include <sstream>

#include "job/job.hpp"
#include "mpi/driver.hpp"

namespace partet::mpi {

inline constexpr char kSetCheckOrder[] = "check";

// Rank 0: the check of a written set, on every rank.
CheckReport check_on_every_rank(const WrittenSet& set);
// A worker's side of a check order (what it finds, rank 0 reports).
void join_set_check(std::istringstream& order, JobStatus& status);

}  // namespace partet::mpi
