// XDMF 3 with its data in one HDF5 file: the format FEM codes on clusters read in parallel
// (DOLFINx's XDMFFile.read_mesh and read_meshtags, ParaView, meshio). A set at PREFIX is
//   PREFIX.xdmf, PREFIX.h5                    the tets ("mesh" grid; cell data "region", "piece"),
//   PREFIX_boundary.xdmf, PREFIX_boundary.h5  the boundary triangles and their markers ("boundary"
//                         grid, the form of DOLFINx mesh tags; 1: input triangle, 2: part of a
//                         split one; its points are PREFIX.h5's),
// ids 64-bit. Two grids in two files because meshio reads one grid per file and DOLFINx reads an
// XDMF file's data from the .h5 of the same name. The HDF5 files are written collectively, every
// rank its own block of the arrays (parallel_hdf5.hpp), so no rank needs the whole mesh to write
// them.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "io/mesh_formats.hpp"

namespace partet {

// The HDF5 datasets: the layout DOLFINx itself writes (Mesh/<grid>, MeshTags/<tags>).
namespace hdf5_dataset {
// PREFIX.h5
inline constexpr const char* geometry = "/Mesh/mesh/geometry";      // points x 3, float64
inline constexpr const char* topology = "/Mesh/mesh/topology";      // tets x 4, int64
inline constexpr const char* region = "/Mesh/mesh/region";          // tets, int32
inline constexpr const char* piece = "/Mesh/mesh/piece";            // tets, int32
// PREFIX_boundary.h5
inline constexpr const char* faces = "/MeshTags/boundary/topology";  // faces x 3, int64
inline constexpr const char* markers = "/MeshTags/boundary/values";  // faces, int32
}  // namespace hdf5_dataset

// Near-equal runs: [first, last) of the part-th of `parts` runs of n rows. Every blocked array
// (written, read back, formatted) is split by this one rule, so a rank's rows agree everywhere.
std::pair<std::size_t, std::size_t> run_of(std::size_t n, int part, int parts);

// One rank's share of a mesh as read back: contiguous runs of the global points, tets and
// boundary faces. Blocks in rank order make the global arrays; point ids are global (from 0).
struct MeshBlock {
  std::vector<Point3> points;
  std::vector<std::array<std::int64_t, 4>> tets;
  std::vector<std::int32_t> tet_region, tet_piece;
  std::vector<std::array<std::int64_t, 3>> faces;
  std::vector<std::int32_t> face_marker;
};

// One rank's share of a mesh to write: the same runs as a MeshBlock, viewed in place. Its ids are
// the mesh's 32-bit ones; HDF5 widens them to the files' 64-bit as it writes, so no rank copies
// its share to widen it (at 33M tets a 64-bit copy of the block, then its bytes for sending, cost
// rank 0 2.4 GB).
struct MeshBlockView {
  ArrayRun<Point3> points;
  ArrayRun<Tet> tets;
  ArrayRun<std::int32_t> tet_region, tet_piece;
  ArrayRun<Triangle> faces;
  ArrayRun<std::int32_t> face_marker;
};

// The columns a block view needs that the mesh does not store: its run's piece numbers when the
// mesh has none (-1), and its faces' markers. They must outlive the view.
struct MadeColumns {
  std::vector<std::int32_t> piece, marker;
};

// Block `part` of `parts` of a whole mesh: the part-th of `parts` near-equal runs of its points,
// tets and faces. `region` is region_of_tets(output.mesh).
MeshBlockView mesh_block_view(const MeshOutput& output, const std::vector<std::int32_t>& region, int part, int parts,
                              MadeColumns& made);

// The XDMF files' text, naming the HDF5 files by their paths relative to them.
std::string xdmf_mesh_text(const MeshTotals& totals, const std::string& mesh_h5);
std::string xdmf_boundary_text(const MeshTotals& totals, const std::string& mesh_h5, const std::string& boundary_h5);

// The paths of the set at PREFIX: .xdmf, _boundary.xdmf, .h5, _boundary.h5.
std::vector<std::string> xdmf_paths(const std::string& prefix);

// Writes the set's files under temporary names into `set`: the HDF5 files through write_hdf5,
// then the XDMF files naming them.
void add_xdmf_files(OutputSet& set, const MeshOutput& output, const std::string& prefix, const Hdf5Write& write_hdf5);


}  // namespace partet
