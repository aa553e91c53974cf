// The TetGen files of a mesh left spread (internal header): rank 0 writes the four files alone,
// in row order, its own rows formatted where it keeps them and every other run of rows streamed
// from the rank keeping that bulk, which formats it; no rank holds the whole mesh, and the files
// are those of the assembled mesh, byte for byte. The exchange (on the writes' tags):
//   order (broadcast): kSpreadTetgenOrder, then the scale exponent; then the bulks' placement
//                      (broadcast);
//   rank -> 0: per bulk it keeps, its piece and the fingerprints of its point and tet rows
//              (5 uint64s each), from which rank 0 makes the set's ID;
//   0 -> rank: per file, once the file is open: "F", the file and the pieces of the runs the rank
//              keeps, in row order (for .neigh, then per run the bulk's faces shared with other
//              blocks); the rank formats them, up to kReadAheadBytes ahead while rank 0 writes the
//              runs before, and sends per run its lines in chunks, "T" + text (or "E" + why not),
//              then ""; rank 0 takes every chunk ordered, even after a failure;
//   0 -> rank: "" once the files are written (or failed): the rank's part is over.
#pragma once
#include <sstream>
#include <string>

#include "io/mesh_formats.hpp"
#include "io/output_set.hpp"
#include "mpi/spread_piece_files.hpp"
#include "stages/spread_mesh.hpp"

namespace partet::mpi {

inline constexpr char kSpreadTetgenOrder[] = "tetgen-spread";

// Rank 0's side: adds PREFIX.node, .ele, .face and .neigh of the spread mesh (its points scaled by
// 2^exponent on the other ranks) to the set. Throws the first failure of any rank.
void add_spread_tetgen_files(OutputSet& set, const SpreadMesh& mesh, const MeshOutput& output,
                             const std::string& prefix, int exponent);

// A worker's side of a kSpreadTetgenOrder (its first line read).
void stream_own_tetgen_rows(std::istringstream& order, BulksForWrites& bulks);

}  // namespace partet::mpi
