// A set's piece files from a mesh left spread (internal header): a .pvtu set's .vtu files or the
// MSH partitions. Each piece's file is written by the rank keeping the piece's bulk, from the
// bulk and the band's tets of that piece; rank 0 writes the seams' file and those of the bulks it
// keeps. No rank holds the whole mesh, and the files are those of the assembled mesh, byte for
// byte. The exchange (order and answers on the writes' tags):
//   order (broadcast): kSpreadPiecesOrder, then the scale exponent, the format, the number of
//                      boundary triangles and where the split ones start (a line each), then per
//                      file its piece, temporary and final name, each ended by '\0'; then the
//                      bulks' placement (broadcast);
//   rank -> 0: the indices of the files it writes (those of the bulks it keeps), as int64s;
//   MSH partitions, rank -> 0: per such file, its bulk's bounds (6 doubles) and open faces
//              (vertex ids ascending): rank 0 finds each partition's boundary triangles;
//   0 -> rank: per such file, "B" then the band's tets of its piece and their solids, and for MSH
//              the band tets' rows, the partition's boundary triangles (element and node tags)
//              and the whole mesh's bounds ("N" alone when rank 0 could not make them);
//   rank -> 0: "I" + the points its files use that it does not keep (the split surface's), all
//              files at once, answered by their coordinates ("" when rank 0 cannot give them);
//   every rank writes its files at once; then, per file, rank -> 0: "" once written, "E" + why
//   not, or, when it cannot open the file's temporary (a directory local to rank 0's node),
//   "A" + the number of arrays, then the file's arrays, which rank 0 writes.
#pragma once
#include <map>
#include <sstream>
#include <vector>

#include "io/mesh_formats.hpp"
#include "mpi/driver.hpp"
#include "stages/seam_chain_band.hpp"
#include "stages/spread_mesh.hpp"

namespace partet::mpi {

inline constexpr char kSpreadPiecesOrder[] = "pvtu-spread";

// Rank 0's side: the piece files (their temporaries made) of the spread mesh, whose points were
// scaled by 2^exponent on the other ranks. Throws the first failure of any rank.
void write_spread_piece_files(MeshFormat format, const SpreadMesh& mesh, const MeshOutput& output, int exponent,
                              const std::vector<PieceFile>& files, RankStats& stats);

// A worker's bulks for the writes of a spread mesh: taken once, scaled back once, and kept for
// every format that needs them.
class BulksForWrites {
 public:
  using Taker = std::function<std::map<int, TetBlock>()>;
  using ChainTaker = std::function<std::map<int, HealedChain>()>;
  explicit BulksForWrites(Taker take, ChainTaker take_chains = nullptr)
      : take_(std::move(take)), take_chains_(std::move(take_chains)) {}
  std::map<int, TetBlock>& get(int exponent);
  // The seam chains it healed and kept (HealOptions::keep_healed), by the index rank 0 gave them.
  std::map<int, HealedChain>& chains();

 private:
  Taker take_;
  ChainTaker take_chains_;
  bool taken_ = false, chains_taken_ = false;
  std::map<int, TetBlock> bulks_;
  std::map<int, HealedChain> chains_;
};

// A worker's side of a kSpreadPiecesOrder (its first line read).
void write_own_piece_files(std::istringstream& order, BulksForWrites& bulks, RankStats& stats);

}  // namespace partet::mpi
