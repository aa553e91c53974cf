// Room for a job's files on the output's filesystem, looked at twice (internal header): before
// the meshing, from the input's counts, so that a full disk costs a second, not the hours of
// meshing before the write; and before the writing, from the mesh's, so that a disk a
// neighbouring job filled meanwhile costs a wait for room, not the mesh. The room asked for is
// least_output_bytes (io/output_size.hpp): a lower bound, so nothing that could have been written
// is refused, and a disk with more room than the bound may still fill up during the write.
#pragma once
#include <string>

#include "io/output_size.hpp"
#include "job/job.hpp"

namespace partet {

// Throws OptionError ("no room for the output: ... Nothing was meshed.") when the output's
// filesystem has less room than the smallest files a mesh of this input can take.
void refuse_output_beyond_disk(const MeshJob& job, const SurfaceMesh& input);

// Returns once the output's filesystem has the room the files of a mesh of these counts take at
// least (at once when it has, or its room is not known). Until then it says so once and looks
// again every 10 s, until job.wait_for_space_minutes have passed since `since` (the job's first
// wait for room: all of them share that time); then throws OutputError (nothing was written),
// with the room needed and what keeps the pieces for a rerun. Returns whether it waited.
bool wait_for_room(const MeshJob& job, const MeshCounts& counts, double since);

// After a write failed with `error` (its temporaries removed, nothing published): when the disk
// ran out of room during the write (ENOSPC: a neighbouring job, or files larger than the bound),
// returns once it has more room than that write had, so the caller writes again and the mesh is
// not lost; when a quota ran out (EDQUOT, which the free space does not show), after a minute.
// Throws OutputError with the error (and, for room, the room the files take at least and what
// keeps the pieces for a rerun) for any other error, or once the wait shared from `since` is over.
void wait_for_more_room(const MeshJob& job, const MeshCounts& counts, const std::string& error, double since);

}  // namespace partet
