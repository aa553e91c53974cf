// Byte encoding of what crosses a process or rank boundary: pieces, piece results and meshing
// failures (Boost.Serialization binary archives, flat arrays as single blocks).
#pragma once
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "partet/errors.hpp"
#include "partet/mesh_types.hpp"
#include "stages/assembly_numbering.hpp"
#include "stages/closure.hpp"
#include "stages/piece.hpp"
#include "stages/kept_band_parts.hpp"
#include "stages/seam_chain_band.hpp"
#include "stages/spread_mesh.hpp"
#include "mesher/tetgen_mesher.hpp"

namespace partet {

// What a worker receives: a piece and the TetGen options to mesh it with, a cap's border to
// triangulate, or a chain of the seams to heal (one tag byte tells which).
enum class TaskKind { piece, cap, chain };
// Throws InternalError on bytes that are no task.
TaskKind task_kind(std::string_view bytes);
// A piece's result to be split where it is meshed (split_where_meshed), in rank 0's attempt
// `attempt`: a worker drops the bulks it kept for earlier attempts.
struct SplitOrder {
  BandSpec spec;
  std::int32_t attempt = 0;
};
std::string serialize_task(const PieceSurface& piece, const TetgenOptions& tetgen, const SplitOrder* split = nullptr);
PieceSurface deserialize_task(std::string_view bytes, TetgenOptions& tetgen, std::optional<SplitOrder>* split = nullptr);
std::string serialize_cap_task(const CapBorder& border);
CapBorder deserialize_cap_task(std::string_view bytes);

// A chain of the seams for a worker to weld and heal (seam_chain_band.hpp: its pieces' shares
// and its split), its index, the healing's options and its regions' TetGen options.
struct ChainTask {
  std::int32_t index = 0;
  ChainShares chain;  // its split, and the shares rank 0 gives
  HealOptions heal;
  TetgenOptions tetgen;
  // The ranks that send the rest of its shares straight to the healing rank (the healing rank
  // itself among them when it keeps some), ascending, and the chain's number in their plan.
  std::vector<std::int32_t> share_ranks;
  std::int32_t shares_of = -1;
  std::string failure;  // why rank 0 could not gather its part: the chain fails once its shares are taken
};
std::string serialize_chain_task(const ChainTask& task);
ChainTask deserialize_chain_task(std::string_view bytes);
// The chain healed there, or its failure.
std::string serialize_chain_outcome(std::int32_t index, const HealedChain& healed);
bool is_chain_outcome(std::string_view reply);
HealedChain deserialize_chain_outcome(std::string_view bytes, std::int32_t& index);

// A cap triangulated elsewhere: its shape, or why its border cannot be closed (the failure of the
// PartitionError it threw), and the seconds it took.
struct CapOutcome {
  CapShape shape;
  std::optional<Failure> failure;
  double seconds = 0;
};
std::string serialize_cap_outcome(const CapOutcome& outcome);
bool is_cap_outcome(std::string_view reply);
CapOutcome deserialize_cap_outcome(std::string_view bytes);

// A meshing run's reply: one tag byte ('R' result, 'F' failure, 'B' a piece split where it was
// meshed: its band, without the bulk, which stays), the seconds and memory it took,
// then the result or failure. (A piece travels as a task, a result or failure as an outcome:
// there is no other form.)
std::string serialize_outcome(const PieceOutcome& outcome);
// Throws InternalError on bytes that are no reply.
PieceOutcome deserialize_outcome(std::string_view bytes);
// Whether a reply holds a result (not a failure or a band).
bool is_result_reply(std::string_view bytes);
// Sets a reply's seconds and memory in place.
void set_reply_figures(std::string& bytes, double seconds, double memory_mb);

// A bulk on its way to rank 0 from the rank that kept it.
std::string serialize_block(const TetBlock& block);
TetBlock deserialize_block(std::string_view bytes);
// A piece's band for the rank that keeps its bulk to grow (BulkStore::grow), and the band grown
// there: the piece split again, without its bulk, which stays.
std::string serialize_band_to_grow(const BandToGrow& band);
BandToGrow deserialize_band_to_grow(std::string_view bytes);
std::string serialize_grown_band(const PieceBand& grown);
PieceBand deserialize_grown_band(std::string_view bytes);
// The plan of the band parts a rank keeps (their places and chains of parts) and the order in
// which rank 0 takes the chains, to the ranks that keep them; and their shares of one chain back.
std::string serialize_share_plan(const std::vector<BandPartPlan>& plans, const std::vector<int>& order,
                                 const std::vector<int>& healers);
void deserialize_share_plan(std::string_view bytes, std::vector<BandPartPlan>& plans, std::vector<int>& order,
                            std::vector<int>& healers);
std::string serialize_chain_shares(const std::vector<ChainShare>& shares);
std::vector<ChainShare> deserialize_chain_shares(std::string_view bytes);
// The numbering's shares of the bulks a rank keeps, from rank 0 (BulkStore::number).
std::string serialize_bulk_shares(const std::vector<BulkShare>& shares);
std::vector<BulkShare> deserialize_bulk_shares(std::string_view bytes);
// The links of the bulks a rank keeps (spread_mesh.hpp), by piece, to rank 0.
std::string serialize_bulk_links(const std::vector<std::pair<int, BlockLinks>>& links);
std::vector<std::pair<int, BlockLinks>> deserialize_bulk_links(std::string_view bytes);
// Where every bulk's rows are and its components' solids (SpreadBulk without its block): what
// rank 0 tells the owners before they write.
std::string serialize_placement(const std::vector<SpreadBulk>& bulks);
std::vector<SpreadBulk> deserialize_placement(std::string_view bytes);
// The healed band's runs (SpreadMesh::band_runs; elsewhere_only: those kept by other ranks than
// 0), for the ranks that keep healed chains.
std::string serialize_band_runs(const std::vector<BandRun>& runs, bool elsewhere_only);
std::vector<BandRun> deserialize_band_runs(std::string_view bytes);

}  // namespace partet
