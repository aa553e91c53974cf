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
// again every 10 s, for job.wait_for_space_minutes at most; then throws OutputError (nothing was
// written), with the room needed and what keeps the pieces for a rerun.
void wait_for_room(const MeshJob& job, const MeshCounts& counts);

// A write error with, when the disk had no room (ENOSPC, EDQUOT), the room the files take at least
// and what keeps the pieces for a rerun; any other error as it is.
std::string with_room_advice(const MeshJob& job, const MeshCounts& counts, const std::string& error);

}  // namespace partet
