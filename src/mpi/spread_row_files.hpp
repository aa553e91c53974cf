// The single files of a mesh left spread whose rows stream from where they are (internal
// header): TetGen's four files, MEDIT's .mesh, one MSH file and one .vtu file (whose arrays rank 0
// compresses as their raw bytes come). Rank 0 writes each file alone,
// in row order, its own rows formatted where it keeps them and every other run of rows streamed
// from the rank keeping that bulk, which formats it; no rank holds the whole mesh, and the files
// are those of the assembled mesh, byte for byte. The exchange (on the writes' tags):
//   order (broadcast): kSpreadRowsOrder, then the scale exponent and the format's name; then the
//                      bulks' placement (broadcast);
//   rank -> 0: per bulk it keeps, its piece, the fingerprints of its point and tet rows (TetGen's
//              files: rank 0 makes the set's ID from them) and its points' bounds (MSH: the
//              model's box), kClaimWords words;
//   0 -> rank: per section of rows of a file, once rank 0 reaches it: "F", the kind of rows
//              (RowLines), the number of row 0 (int64) and the pieces of the runs the rank keeps,
//              in row order (for TetGen's .neigh, then per run the bulk's faces shared with other
//              blocks). In a section of points, a run can also be a share of the split surface's
//              points, which rank 0 keeps (kGivenPoints): rank 0 deals them out so that every rank
//              formats about as many rows, and sends per such run the number of its first row
//              (int64), then its points. The rank formats its runs, up to kReadAheadBytes ahead
//              while rank 0 writes the runs before, and sends per run its text in chunks, "T" +
//              text (or "E" + why not), then ""; rank 0 takes every chunk ordered, even after a
//              failure;
//   0 -> rank: "" once the files are written (or failed): the rank's part is over;
// then, for TetGen's files, the .face file's rows, formatted on every rank (a "rows" order).
// Rank 0's side is in spread_row_files.cpp, the other ranks' in stream_own_rows.cpp, what both
// say in spread_row_order.hpp.
#pragma once
#include <sstream>
#include <string>

#include "io/mesh_formats.hpp"
#include "io/output_set.hpp"
#include "mpi/spread_piece_files.hpp"
#include "stages/spread_mesh.hpp"

namespace partet::mpi {

inline constexpr char kSpreadRowsOrder[] = "rows-spread";

// Rank 0's side: adds the files of `format` (tetgen, vtu, medit, msh or msh-binary) for PREFIX of the
// spread mesh (its points scaled by 2^exponent on the other ranks) to the set. Throws the first
// failure of any rank. TetGen's .face file, whose rows rank 0 keeps, is written after the
// exchange with face_lines (every rank formats a share; empty: here).
void add_spread_row_files(OutputSet& set, MeshFormat format, const SpreadMesh& mesh, const MeshOutput& output,
                          const std::string& prefix, int exponent, const TetgenLines& face_lines = {});

// A worker's side of a kSpreadRowsOrder (its first line read).
void stream_own_rows(std::istringstream& order, BulksForWrites& bulks);

}  // namespace partet::mpi
