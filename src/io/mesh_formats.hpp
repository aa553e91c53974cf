// Writing the final tet mesh in the formats users open: VTK XML (.vtu, and .pvtu with one .vtu
// per piece), Gmsh MSH 4.1 (ASCII or binary; one file, or one per partition: msh.hpp) and MEDIT
// (.mesh). The MPI driver has every rank write its share of the sets with one file per piece.
// TetGen's own files are in tetgen_files.hpp. Every writer writes exactly one file, to the path it is given (the caller
// publishes a set of files atomically under their final names). Throws OutputError.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "common/point_ids.hpp"
#include "io/output_set.hpp"
#include "io/row_lines.hpp"
#include "io/tetgen_files.hpp"
#include "partet/mesh_types.hpp"
#include "stages/info.hpp"

namespace partet {

enum class MeshFormat { tetgen, vtu, pvtu, msh, msh_binary, msh_parts, msh_parts_binary, medit, xdmf };

// Names on the command line ("tetgen", "vtu", "pvtu", "msh", "msh-binary", "msh-parts",
// "msh-parts-binary", "medit", "xdmf"), in order.
const std::vector<std::string>& mesh_format_names();
// Throws OptionError naming the valid names.
MeshFormat mesh_format(const std::string& name);
std::string mesh_format_name(MeshFormat format);
// The format an output path's extension names (.node .vtu .pvtu .msh .mesh .xdmf), and the path
// without it; false when the extension names none.
bool split_format_extension(const std::string& path, MeshFormat& format, std::string& prefix);

// The files a format writes for PREFIX, as far as they are known before the run: TetGen's four;
// for pvtu the index, whose piece files PREFIX_p<i>.vtu and PREFIX_seams.vtu follow the mesh; for
// the MSH partitions the first, PREFIX_1.msh (PREFIX_2.msh ... follow the mesh); for xdmf
// PREFIX.xdmf, PREFIX_boundary.xdmf and PREFIX.h5 (see xdmf.hpp).
std::vector<std::string> format_paths(MeshFormat format, const std::string& prefix);
// The files the format writes for PREFIX that follow the mesh (a .pvtu set's piece files, the MSH
// partitions, by name), as a family; none for the other formats.
std::vector<FileFamily> mesh_named_files(MeshFormat format, const std::string& prefix);

// The MSH partition files: PREFIX_<partition>.msh, from 1. partition_file_prefix: whether path is
// one of them (a number without leading zeros), and its PREFIX.
std::string partition_file(const std::string& prefix, std::size_t partition);
bool partition_file_prefix(const std::string& path, std::string& prefix);

// What the writers write.
struct MeshOutput {
  const TetMesh& mesh;                    // positively oriented tets; mesh.piece per tet if known
  const std::vector<Triangle>& boundary;  // the input triangles, outward, in mesh numbering
  // Faces from this index on are parts of input triangles split by points on the surface
  // (--allow-split-faces): boundary marker 2 instead of 1, in the formats that carry one.
  std::size_t split_from = SIZE_MAX;
};

// Connected solids, numbered from 1 in the order of their first tet (MEDIT references, VTU and
// XDMF cell data). From the neighbours when present, else from the tets.
std::vector<std::int32_t> region_of_tets(const TetMesh& mesh);

// A run of an array, viewed where it is (its owner keeps it alive).
template <class T>
struct ArrayRun {
  const T* data = nullptr;
  std::size_t size = 0;
};

template <class T>
ArrayRun<T> run_of(const std::vector<T>& values) {
  return {values.data(), values.size()};
}

template <class T>
std::string_view bytes_of(ArrayRun<T> run) {
  return {reinterpret_cast<const char*>(run.data), run.size * sizeof(T)};
}

// Bytes viewed as a run of T (they must be aligned for T, as received or allocated bytes are);
// false when they are not a whole number of T.
template <class T>
bool as_run(std::string_view bytes, ArrayRun<T>& run) {
  run = {reinterpret_cast<const T*>(bytes.data()), bytes.size() / sizeof(T)};
  return bytes.size() % sizeof(T) == 0;
}

// Byte arrays viewed as runs, in order; false when their number or a size does not fit.
template <class... T>
bool as_runs(const std::vector<std::string_view>& arrays, ArrayRun<T>&... runs) {
  if (arrays.size() != sizeof...(T)) return false;
  std::size_t i = 0;
  return (as_run(arrays[i++], runs) && ...);
}

// The cells of one .vtu file, viewed in place: tets with their points numbered from 0 (xyz: 3
// doubles per point), VTK's connectivity, offsets and cell types, and the cell data write_vtu
// describes. A rank that receives a piece file's cells writes them from the bytes it received.
struct VtuCellsView {
  ArrayRun<double> xyz;
  ArrayRun<std::int64_t> connectivity, offsets;
  ArrayRun<std::uint8_t> types;
  ArrayRun<std::int32_t> piece, region;
  ArrayRun<std::int64_t> global_ids;  // a .pvtu piece file's (else empty): each point's id in the whole mesh
};
// The cells of a .vtu file: the tets of one piece value with their points renumbered, or all
// tets and points as they are.
struct VtuCells {
  std::vector<double> xyz;
  std::vector<std::int64_t> connectivity, offsets;
  std::vector<std::uint8_t> types;
  std::vector<std::int32_t> piece, region;
  std::vector<std::int64_t> global_ids;  // a piece file's: each point's id in the whole mesh

  VtuCellsView view() const {
    return {run_of(xyz),   run_of(connectivity), run_of(offsets),   run_of(types),
            run_of(piece), run_of(region),       run_of(global_ids)};
  }
};
// Tets and a region (solid) per tet, viewed where they are; ids gives the whole mesh's id of each
// of their ids.
struct TetsWithRegion {
  const std::vector<Tet>* tets;
  const std::vector<std::int32_t>* region;
  PointIds ids = {};
};
// A .pvtu piece file's cells from blocks of one piece value's tets in row order (a mesh left
// spread: a piece's bulk, then the band's tets of that piece): the points renumbered from 0 in
// order of first use, with their ids in the whole mesh, as the assembled mesh's piece files
// number them. The coordinates are the caller's to set: xyz, 3 per global id.
VtuCells piece_file_cells(int piece, const std::vector<TetsWithRegion>& blocks);
// The point data of a .pvtu set's piece files that numbers their points as in the whole mesh
// (from 0, as in the single .vtu and, less one, the TetGen and MSH files): VTK's global ids.
inline constexpr const char* kGlobalPointIds = "GlobalPointIds";

// Writes one .vtu file of these cells into `path`, which must exist (an OutputSet's temporary);
// errors name `shown`.
void write_vtu_file(const VtuCellsView& cells, const std::string& path, const std::string& shown);

// The rows of a single .vtu file, wherever they are (like MeshRows): write(out, lines) gives
// every row of one raw array (vtu_points, vtu_connectivity, vtu_piece, vtu_region), in order.
struct VtuRows {
  std::uint64_t points = 0, tets = 0;
  std::function<void(ByteSink& out, RowLines lines)> write;
};
VtuRows vtu_rows(const MeshOutput& output);

// VTK XML UnstructuredGrid, binary appended data, zlib-compressed. Cell data: "piece" (the piece
// that meshed the tet, -1: re-meshed after the merge, at a cut or by the polish) and "region" (the
// connected solid it belongs to, from 1). Like write_vtu_file, into `path`, which must exist (an
// OutputSet's temporary); errors name `shown`.
void write_vtu(const VtuRows& rows, const std::string& path, const std::string& shown);

// The .pvtu index naming one .vtu per piece value (each as write_vtu writes, with just that
// piece's tets and the points they use, numbered from 0, and kGlobalPointIds their ids in the whole mesh); the names
// are stored as given (relative to the .pvtu's directory).
void write_pvtu(const MeshOutput& output, const std::string& path, const std::vector<std::string>& piece_files);

// The piece indices a .pvtu set has files for, in order (the -1 group included when present).
std::vector<int> pieces_in(const MeshOutput& output);

// The rows of points and tets of a single MSH or MEDIT file, wherever they are: the assembled
// mesh's (mesh_rows), or a spread mesh's, streamed from the ranks keeping its parts.
struct MeshRows {
  std::uint64_t points = 0, tets = 0;
  Bounds box;  // of the points (MSH's model; all zero when not asked for)
  // Writes every row of points (a points kind) or of tets, in order; msh_tet's tags from number_from.
  std::function<void(BufferedFile& out, RowLines lines, std::int64_t number_from)> write;
};
MeshRows mesh_rows(const MeshOutput& output, bool box);

// Gmsh MSH 4.1: nodes, tetrahedra (physical group 1 "volume") and the boundary triangles
// (physical group 2 "boundary"; the parts of split input triangles, from split_from on: physical
// group 3 "split boundary", a second surface entity), with entities for the volume and the
// boundary surfaces. Errors name `shown`.
void write_msh(const MeshRows& rows, const std::vector<Triangle>& boundary, std::size_t split_from,
               const std::string& path, const std::string& shown, bool binary);

// MEDIT .mesh (ASCII, version 2): Vertices, Tetrahedra (reference = region) and Triangles
// (reference 1: the boundary; 2: parts of split input triangles, from split_from on).
void write_medit(const MeshRows& rows, const std::vector<Triangle>& boundary, std::size_t split_from,
                 const std::string& path, const std::string& shown);

// Writes the HDF5 files of an XDMF set (the mesh's and the boundary's) to temporary paths;
// returns the counts of points, tets and faces written. The MPI driver gives one that has every
// rank write its block at once.
struct MeshTotals {
  std::uint64_t points = 0, tets = 0, faces = 0;
};
struct Hdf5Paths {
  std::string mesh, boundary;              // where to write
  std::string mesh_shown, boundary_shown;  // the final names, for messages
};
using Hdf5Write = std::function<MeshTotals(const MeshOutput& output, const Hdf5Paths& paths)>;

// One file of a set with a file per piece (a .pvtu set's .vtu files, the MSH partitions): its
// piece value (-1: the seams), its temporary (already created; written in place) and its final
// name (for messages).
struct PieceFile {
  int piece = 0;
  std::string temporary, shown;
};
// A piece file's content as its arrays' bytes, viewed in place: what rank 0 makes and sends the
// rank that writes the file.
using PieceArrays = std::vector<std::string_view>;
// A piece value's arrays, made for its own file; valid until the next call.
using PieceArraysOf = std::function<PieceArrays(int piece)>;
// A .vtu piece file's arrays (what a rank that cannot open the file sends the rank that can).
PieceArrays arrays_of(const VtuCellsView& cells);
// Writes one piece file of a set in `format` (pvtu, msh-parts, msh-parts-binary) from its arrays
// into `path`, which must exist; errors name `shown`. Throws OutputError when the arrays do not
// fit together (lost or cut bytes).
void write_piece_file(MeshFormat format, const PieceArrays& arrays, const std::string& path, const std::string& shown);
// Writes every piece file of a set (write_piece_file on each file's arrays). The MPI driver's
// writer deals them out to the ranks, so they write at once.
using PieceFilesWrite =
    std::function<void(MeshFormat format, const std::vector<PieceFile>& files, const PieceArraysOf& arrays_of)>;

// How the other ranks take part in writing (the MPI driver's): hdf5 writes an XDMF set's HDF5
// files (required for xdmf); tetgen_lines formats TetGen files' lines; piece_files writes the
// piece files of a .pvtu set or the MSH partitions (empty: here, alone). With a mesh left spread
// (MeshOutput's mesh empty), the piece values and the writer of a set's piece files (.pvtu, MSH
// partitions) from where the mesh's parts are, and the writer of the single-file formats whose rows stream from
// there (TetGen's files, .vtu, MSH, MEDIT: spread_rows).
struct RankWriters {
  Hdf5Write hdf5;
  TetgenLines tetgen_lines;
  PieceFilesWrite piece_files;
  std::vector<int> spread_pieces;
  std::function<void(MeshFormat format, const std::vector<PieceFile>& files, const MeshOutput& output)>
      spread_piece_files;
  std::function<void(OutputSet& set, MeshFormat format, const MeshOutput& output, const std::string& prefix)>
      spread_rows;
  // Before the files are written again after a write failed (a full disk): the other ranks forget
  // that write's failure.
  std::function<void()> again;
};

// Writes the format's files for PREFIX under temporary names into `set` (published together).
void add_mesh_files(OutputSet& set, MeshFormat format, const MeshOutput& output, const std::string& prefix,
                    const RankWriters& writers);

}  // namespace partet
