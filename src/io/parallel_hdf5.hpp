// The HDF5 file of an XDMF set (xdmf.hpp), written collectively: every rank writes its own block
// of the arrays at the same time through parallel HDF5 (MPI-IO). Part of the MPI layer's
// library: the core knows nothing of MPI.
#pragma once
#include <mpi.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "common/point_ids.hpp"
#include "io/xdmf.hpp"

namespace partet {

// Why a rank cannot take part in a write.
enum class WriteTrouble : int { none = 0, no_block = 1, file_not_seen = 2 };

// Collective over comm: writes the HDF5 files from every rank's block, the blocks in rank order
// (each rank's first rows from an exclusive prefix sum of the counts). The paths are absolute and
// the (empty) files exist already, made by rank 0: a rank that does not see them is on a
// filesystem rank 0 does not share, and must not write a file of its own. Returns the totals on
// every rank. Throws OutputError (naming the final file, and the rank in trouble) on every rank
// when any rank fails. `step_ended` is called after each collective step (a write call of at most
// 256 MB per rank, an agreement), for a watch over the write (mpi/collective_watch.hpp).
MeshTotals write_mesh_hdf5(MPI_Comm comm, const MeshBlockView& block, const Hdf5Paths& paths,
                           WriteTrouble trouble = WriteTrouble::none, const std::function<void()>& step_ended = {});

// A rank's rows of the mesh, at the rows they have in the whole mesh (any number of runs, in any
// order): what the owners of a mesh's parts write where the parts are, no rank holding the whole.
struct MeshRowRuns {
  struct Points {
    std::uint64_t first = 0;
    ArrayRun<Point3> points;
  };
  struct Tets {
    std::uint64_t first = 0;
    ArrayRun<Tet> tets;
    ArrayRun<std::int32_t> region, piece;
    PointIds ids;  // the whole mesh's id of each of the tets' ids
  };
  std::vector<Points> points;
  std::vector<Tets> tets;
  std::uint64_t first_face = 0;
  ArrayRun<Triangle> faces;
  ArrayRun<std::int32_t> face_marker;
};

// Collective over comm, as write_mesh_hdf5, from every rank's runs; `totals` are the whole mesh's
// (every rank gives the same). Throws OutputError as write_mesh_hdf5 does.
MeshTotals write_mesh_runs_hdf5(MPI_Comm comm, const MeshRowRuns& runs, const MeshTotals& totals,
                                const Hdf5Paths& paths, WriteTrouble trouble = WriteTrouble::none,
                                const std::function<void()>& step_ended = {});

// Collective over comm: each rank reads its run of the rows (the rank-th of comm's size near-equal
// runs, as mesh_block deals them) of the points, tets, boundary faces and markers of an XDMF
// set's HDF5 files (not region or piece). Sets the totals. Throws InputError naming the file on
// every rank when any rank cannot read it.
MeshBlock read_mesh_hdf5(MPI_Comm comm, const std::string& mesh_h5, const std::string& boundary_h5, MeshTotals& totals);

// The HDF5 files written by this process alone (MPI must be initialized).
MeshTotals write_hdf5_here(const MeshOutput& output, const Hdf5Paths& paths);

}  // namespace partet
