// The rows of points and tets in the single-file formats (TetGen's .node/.ele/.neigh, MEDIT,
// MSH, the raw arrays of a .vtu file), formatted by one formatter into a file, a string or a
// sink (internal header): a rank that formats its part of a mesh and sends the text gives the
// bytes the file would hold.
#pragma once
#include <cstdint>
#include <string>

#include "common/point_ids.hpp"
#include "partet/mesh_types.hpp"

namespace partet {

class BufferedFile;

// What a run of rows is written as (row i of the whole file: index i, number number_from + i).
enum class RowLines : std::uint8_t {
  tetgen_node,      // "i x y z"
  tetgen_ele,       // "i a b c d" (from 0)
  tetgen_neigh,     // "i a b c d" (tets, -1: none; rows of 4 int64: a mesh may have 2^31 tets or more)
  medit_vertex,     // "x y z 0"
  medit_tet,        // "a b c d region" (from 1)
  msh_node,         // "x y z " (the node tags are written apart)
  msh_tet,          // "tag a b c d " (tag: the number, nodes from 1)
  msh_node_binary,  // the same as doubles and size_ts
  msh_tet_binary,
  vtu_points,        // VTK's raw arrays: 3 doubles per point,
  vtu_connectivity,  // 4 Int64 per tet,
  vtu_piece,         // an Int32 per tet (RowsToFormat::piece),
  vtu_region,        // an Int32 per tet (RowsToFormat::region)
};
inline constexpr int kRowLinesKinds = 13;

// Whether the rows are points (Point3) or tets (Tet; tetgen_neigh: 4 int64).
bool formats_points(RowLines lines);

// The bytes of one row as RowsToFormat packs it.
std::size_t row_bytes(RowLines lines);

// A run of rows, packed where they are kept: `count` points or tets from row `first` of the file.
struct RowsToFormat {
  const void* data = nullptr;
  std::size_t count = 0;
  std::int64_t first = 0;
  std::int64_t number_from = 0;          // msh_tet: the tag of row 0
  const std::int32_t* region = nullptr;  // medit_tet, vtu_region: per row of the run
  const std::int32_t* piece = nullptr;   // vtu_piece: per row of the run
  PointIds ids{};                        // tets: the mesh's id of each of their (32-bit) ids
};

// Where bytes go that are not written as they are (a .vtu file's arrays, compressed first).
class ByteSink {
 public:
  virtual ~ByteSink() = default;
  virtual void bytes(const void* data, std::size_t size) = 0;
};

// Appends the rows' text (bytes, for the binary kinds) to `text`.
void append_row_lines(std::string& text, RowLines lines, const RowsToFormat& rows);
// Writes the same bytes into `out`.
void write_row_lines(BufferedFile& out, RowLines lines, const RowsToFormat& rows);
// The same into a sink, formatted a chunk of rows at a time.
void write_row_lines(ByteSink& out, RowLines lines, const RowsToFormat& rows);

}  // namespace partet
