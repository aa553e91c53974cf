// Writing with every rank (step 9; internal header). Rank 0 broadcasts an order ("hdf5", "rows"
// or "pieces", then its details on further lines), and sends each rank its block; an empty order
// ends the writes. (Until the pieces' tets stay with the ranks that meshed them, rank 0 deals the
// blocks out.)
// - hdf5: the HDF5 files of an XDMF set, written by every rank at once (parallel HDF5).
// - rows: the lines of a TetGen file; each rank formats its block of rows while rank 0 formats
//   its own, then sends the text back in chunks ("T" + text; "E" + a message when it cannot;
//   then an empty chunk), which rank 0 writes in order after its own block. The block comes in
//   parts of kRowPart rows, so a rank frees each part as it formats it: it holds its text and
//   one part, not its whole block beside its text.
// - pieces: the files of a set with one file per piece (a .pvtu set's, the MSH partitions); each
//   rank that sees the output directory writes some, each file going to whichever rank is free
//   (see PieceFileDealer).
// - hdf5-spread, pvtu-spread: the same files from a mesh left spread, each part written by the
//   rank that keeps it (spread_piece_files.hpp).
// - again: a write failed for want of room and rank 0 found more; the files are written again
//   (every rank still holds its part), so each rank forgets that write's failure.
#pragma once
#include <functional>
#include <map>

#include "io/mesh_formats.hpp"
#include "job/job.hpp"
#include "mpi/driver.hpp"
#include "stages/seam_chain_band.hpp"
#include "stages/spread_mesh.hpp"

namespace partet::mpi {

// Rank 0's writers, which have every rank of a job on `size` ranks take part. With a spread
// mesh (MeshResult::spread; the input meshed scaled by 2^scale_exponent), the XDMF set's rows are
// written by their owners (which must outlive the writers).
RankWriters rank_writers(int size, RankStats& stats, SpreadMesh* spread = nullptr, int scale_exponent = 0);
// Rank 0: no more writes.
void end_writes();
// A worker's bulks, numbered, by piece (Worker::take_kept_bulks): for a spread mesh's write.
using KeptBulksTaker = std::function<std::map<int, TetBlock>()>;
using KeptChainsTaker = std::function<std::map<int, HealedChain>()>;
// A worker's side: joins each write rank 0 orders until it says there are no more.
void join_writes(JobStatus& status, RankStats& stats, const KeptBulksTaker& take_bulks,
                 const KeptChainsTaker& take_chains = nullptr);

}  // namespace partet::mpi
