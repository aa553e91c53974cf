// `partet check` on an XDMF set, TetGen files, or the sets mesh_read.hpp reads (MSH, VTK, MEDIT), on any number of
// ranks: each rank reads and checks its own part of the tets and boundary faces; what spans ranks
// (a face's two tets, an edge, a vertex's use, a boundary triangle against the input) is decided
// by the rank its key hashes to. So no rank holds the whole mesh, and a mesh too large for one
// process can still be verified. It checks what check_mesh checks for TetGen files, exact
// boundary rule: ids in range, every tet positively oriented (exact predicate), every triangle in
// at most two tets on opposite sides, the boundary faces equal to the tets' free faces (outward)
// and, by exact coordinates, to the input triangles, no unused or duplicate vertices, V-E+F-T
// against the input's Euler characteristic, and the tets' volume against the input's.
#pragma once
#include <mpi.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "partet/mesh_types.hpp"
#include "stages/quality.hpp"

namespace partet {

struct DistributedCheckReport {  // the same on every rank
  std::vector<std::string> violations;
  std::int64_t vertices = 0, tets = 0, boundary_faces = 0;
  double tet_volume = 0, surface_volume = 0;
  long euler_mesh = 0, euler_expected = 0;
  MeshQuality quality;  // as one process finds it (the averages summed in another order)
  std::optional<ZoneQuality> zones;  // the seam zone's and the rest's, when the planes were given
  bool ok() const { return violations.empty(); }
};

// Collective over comm. Rank 0 reads the input surface; every rank reads its rows of PREFIX.h5
// and PREFIX_boundary.h5. Throws InputError (on every rank) when a file cannot be read.
DistributedCheckReport check_xdmf_set(MPI_Comm comm, const std::string& input_path, const std::string& prefix);

// The same check on a set mesh_read.hpp reads (PATH, one of its files): an MSH file or partition
// set, a .vtu or a .pvtu set, a MEDIT .mesh. Rank 0 reads PATH, which names the set's other files,
// and each rank reads every size-th of them; the points go to their owners by id. So a set too
// large for one process can be checked on several. VTK files list no boundary triangles: the
// faces in one tet are checked against the input instead. Throws InputError (on every rank) when
// a file cannot be read, a point has other coordinates in another file, or an id between the
// lowest and the highest is missing.
DistributedCheckReport check_mesh_file_set(MPI_Comm comm, const std::string& input_path, const std::string& path);

// The same check on TetGen files PREFIX.node .ele .face .neigh as partet writes them (each file
// ending with its set ID): every rank reads the same share of each file's bytes (whole lines);
// points, tets and .neigh rows go to their owners by index. Besides the checks above, the .neigh
// rows must name the tets the faces imply and all four files the same set ID. Throws InputError
// (on every rank) on a missing file, a malformed row, an index missing, repeated or out of range,
// or a set without an ID (not partet's: its faces are not promised outward).
DistributedCheckReport check_tetgen_set(MPI_Comm comm, const std::string& input_path, const std::string& prefix);

// A set a run wrote and has not published yet (`mesh --check` on several ranks, with the mesh
// left where its parts are): the same checks on its files under their temporary names (each
// final name followed by `suffix`), against the input rank 0 holds, and the quality of the seam
// zone and of the rest given the cut planes. Collective over comm, as above.
struct UnpublishedSet {
  std::string prefix;                 // absolute, the same on every rank
  std::string suffix;                 // the temporaries' (OutputSet::temporary_name_suffix)
  const SurfaceMesh* input = nullptr;  // rank 0's
  std::vector<CutPlane> planes;
};
DistributedCheckReport check_unpublished_tetgen_set(MPI_Comm comm, const UnpublishedSet& set);
DistributedCheckReport check_unpublished_xdmf_set(MPI_Comm comm, const UnpublishedSet& set);

}  // namespace partet
