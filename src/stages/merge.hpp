// Merge: weld the pieces' tet meshes at the caps into one mesh with global numbering.
#pragma once
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include "partet/mesh_types.hpp"
#include "stages/assembly_numbering.hpp"
#include "stages/piece.hpp"
#include "stages/seam_band.hpp"
#include "stages/seam_chain_band.hpp"
#include "stages/seam_chains.hpp"
#include "stages/spread_mesh.hpp"

namespace partet {

struct StepClock;
struct ChainShare;
struct BandPartPlan;

// Where a welder keeps the pieces' bulks between their split and the assembly when not in its
// own memory: the paper's memory mode (scratch files, io/scratch_bulks.hpp), and the ranks that
// meshed them (the MPI driver). Healing never touches a bulk, so it can wait outside the process.
class BulkStore {
 public:
  virtual ~BulkStore() = default;
  // Takes piece p's bulk (a copy); false when it cannot, and the welder keeps it.
  virtual bool put(int piece, const TetBlock& bulk) = 0;
  // Piece p's bulk as it was put, once. Throws Error when it was lost.
  virtual TetBlock take(int piece) = 0;
  // Whether a band can grow where this store keeps the bulk (grow), so that the bulk does not
  // travel: the MPI driver's owners.
  virtual bool grows_bands() const { return false; }
  // Grows piece band.index's band with the bulk kept here (grow_band): the piece split again, its
  // new bulk kept here in place of the old one and not in the result (bulk_tets and
  // bulk_steiner_points count it). Only when grows_bands.
  virtual PieceBand grow(BandToGrow&& /*band*/) { throw InternalError("this store cannot grow a band"); }
  // Before the assembly takes them: the numbering's shares of the bulks kept here. A store that
  // can numbers them where they are (number_bulk; the MPI driver's owners, all at once) and gives
  // them back numbered; by default the welder numbers them as they come back.
  virtual void number(const std::vector<BulkShare>& /*shares*/) {}
  // For a mesh left spread (Welder::spread), after number: asks for the links (block_links, with
  // input_vertices) of every bulk kept here, which a store may make meanwhile (the owners, while
  // the welder links its own bulks); links returns them, by piece.
  virtual void ask_links(std::int32_t /*input_vertices*/) {}
  virtual std::vector<std::pair<int, BlockLinks>> links() { return {}; }
  // Band parts kept with the bulks (PieceBand::band_kept, add_split; the MPI driver's owners):
  // piece p's band part back (band, band_steiner and band_tets, in the store's Steiner ids),
  // once, when the band must be welded after all. Throws Error when it was lost.
  virtual PieceBand take_band(int piece);
  // Before the chains are welded: the band parts kept here cut into the chains' shares (plans:
  // those parts' places, in the store's Steiner ids, and chains of parts), each chain's sent to the
  // rank that heals it (healers, by chain); `shares` then gives those of the chains healed by the
  // welder's rank (0) chain by chain, in `order`.
  virtual void cut_shares(const std::vector<BandPartPlan>& /*plans*/, const std::vector<int>& /*order*/,
                          const std::vector<int>& /*healers*/) {}
  virtual std::vector<ChainShare> shares(int chain);
  // The healed chains kept where they healed (HealOptions::keep_healed), back in full, each with
  // the index it was healed as; once.
  virtual std::vector<std::pair<int, HealedChain>> take_chains() { return {}; }
};

// Welds the pieces' meshes as they arrive, in any order, so most of the merge overlaps the
// meshing of the last pieces. The mesh's points are the split surface's (input, cut and cap
// points), then each piece's Steiner points in piece order; tets follow in piece order. Cap
// vertices are welded by id, never by coordinates; neighbours across caps are restored by
// matching the open faces that can lie on a cap (those without an input vertex).
class Welder {
 public:
  // Both must outlive the welder; the pieces are ordered by index.
  Welder(const SplitSurface& split, const std::vector<PieceSurface>& pieces);

  // Before the first add: each piece is split into its band and its bulk as it arrives (while
  // other pieces are still being meshed) rather than all at once in finish_band, which then only
  // moves the tets its neighbours' crossings reach into the band. Only with one layer (the
  // default: the tets a crossing reaches are the band's last layer and reach no further);
  // otherwise this does nothing.
  void split_on_arrival(const BandSpec& spec);
  // Before the first add: each bulk goes to the store as soon as it is split off (it must outlive
  // the welder's use of it) and comes back only to be assembled or rejoined.
  void keep_bulks_in(BulkStore& store) { store_ = &store; }
  // Renumbers a piece's mesh into global vertex ids (its Steiner points provisionally: they
  // are numbered after all earlier pieces' at the end) and frees its arrays. Throws
  // InternalError when it does not match its piece or arrives twice.
  void add(PieceTetMesh&& result);
  // After split_on_arrival: a piece split where it was meshed (split_where_meshed), its bulk
  // kept by `owner` (which must outlive the welder's use of it) until it is needed.
  void add_split(PieceBand&& split, BulkStore& owner);
  bool has(int piece) const;
  // Gives a piece's mesh back in its local numbering, as it was added (a retry keeps the pieces it
  // does not change).
  PieceTetMesh take_back(int piece);

  // Once every piece is in: the welded mesh (the welder is then empty). Its first points are
  // the split surface's, given here (moved in by a caller that no longer needs them, so they are
  // held once); its arrays have room for what seam healing adds (see kHealingRoom).
  TetMesh finish(std::vector<Point3> split_points);

  // Once every piece is in, instead of finish: splits each piece into its band (seam_band.hpp;
  // spec.split_point_count is set here) and its bulk, and welds the bands alone. The band mesh is
  // numbered as the whole welded mesh would be, except that only the bands' Steiner points follow
  // the split surface's. Its tets are the bands' in piece order.
  TetMesh finish_band(std::vector<Point3> split_points, BandSpec spec);
  // finish_band in two steps: the pieces split into their band parts and bulks (the band parts
  // then grown, their links made), then the band parts welded into the band mesh.
  void split_bands(BandSpec spec);
  TetMesh weld_bands(std::vector<Point3> split_points);
  // Instead of weld_bands, once every chain was welded from the band parts (BandPartChains,
  // chain_share): the band mesh's points alone, numbered as weld_bands numbers them, for the
  // healed chains to fill (add_healed_chains). The band parts go.
  TetMesh band_points(std::vector<Point3> split_points);
  // Between the two: piece p's band part (its Steiner point b is split_point_count + b), and where
  // each piece's band part goes in the welded band (chain_share).
  // A band part kept where its piece was split (band_part_here false) has no tets here: its store
  // cuts its shares (cut_kept_shares before the first chain, sending each chain's to the rank
  // that heals it, then kept_shares chain by chain, in `order`, for those healed here), and gives
  // it back when the band is welded after all.
  const TetBlock& band_part(std::size_t p) const { return blocks_.at(p); }
  bool band_part_here(std::size_t p) const { return !band_elsewhere_.at(p).kept; }
  std::vector<BandPartPlace> band_part_places() const;
  void cut_kept_shares(const std::vector<std::vector<int>>& chain_of_part, const std::vector<int>& order,
                       const std::vector<int>& healers);
  std::vector<ChainShare> kept_shares(int chain);
  // The split surface's points these pieces' band parts use, ascending: those a chain of them may
  // use (its split: chain_split).
  std::vector<std::int32_t> band_split_points(const std::vector<std::size_t>& pieces) const;
  // After split_bands, once: the links of each piece's band (band_part_links), which give the
  // chains (seam_chain_plan) without the welded band.
  std::vector<BandPartLinks> take_band_links() { return std::move(band_links_); }
  // After the band was healed with its points kept: the mesh of every bulk in piece order, then
  // the healed band, joined across the caps and the bands' edges. Points: the split surface's,
  // every piece's Steiner points in piece order, then those healing added; those no tet uses are
  // dropped (as healing the whole welded mesh drops them), keeping order.
  // (drop_unused false: no point is dropped, so the mesh is numbered as the whole welded mesh
  // would be, and healing can go on over it.)
  TetMesh assemble(TetMesh&& healed_band, bool drop_unused = true);
  // The same in two steps: the numbering, made from the healed band alone (once: the bands'
  // Steiner maps move into it; each bulk's share, for_bulk, numbers it wherever it is kept), then
  // the assembly with it.
  AssemblyNumbering numbering(const TetMesh& healed_band, bool drop_unused = true,
                              const std::vector<std::int32_t>& used_elsewhere = {});
  TetMesh assemble(TetMesh&& healed_band, const AssemblyNumbering& numbering);
  // Instead of the assembly, when only formats written from the parts are: the mesh left where
  // its parts are (spread_mesh.hpp). The bulks kept by an owner's store (add_split) are numbered
  // there and stay; those kept here, or in this process's own store (keep_bulks_in), move into
  // the result, numbered. With faces_across, the tets across the blocks' shared faces too (for
  // TetGen's .neigh). `chains`: the band's links, healed chain by chain (add_healed_chains), when
  // the band is made of them; else found here. The welder is then empty.
  // A chain kept by the rank that healed it (BandChainLinks::kept_on) has its rows in the band
  // there (SpreadMesh::band_runs); then no faces_across.
  SpreadMesh spread(TetMesh&& healed_band, bool faces_across = true, std::vector<BandChainLinks>&& chains = {});
  // The healed chains kept where they healed, back in full (by their place in the healing order),
  // when the band must be welded after all.
  std::vector<std::pair<int, HealedChain>> take_kept_chains();
  // Whether an owner's store keeps a bulk (the pieces were split where they were meshed).
  bool keeps_bulks_elsewhere() const;
  // The tets the bulks hold (after finish_band, or split_bands); the tets the band parts hold
  // (after split_bands, before weld_bands).
  std::size_t bulk_tet_count() const;
  std::size_t band_tet_count() const;

 private:
  using Block = TetBlock;
  TetMesh weld_blocks(std::vector<Point3> split_points, std::vector<Block>& blocks) const;
  // Before the band mesh takes the split's points: room for every Steiner point the assembly adds.
  void reserve_for_assembly(std::vector<Point3>& split_points) const;
  // Splits piece p's block (blocks_[p]) into its band (left in blocks_[p]) and its bulk (bulks_[p]).
  void split_piece(std::size_t p, const std::vector<std::int8_t>& depth);
  // Piece p's band and bulk joined again into its block as it was added.
  void rejoin(std::size_t p);
  // After pieces were split on arrival: each band grows by the tets its neighbours' crossings reach.
  void take_crossings();
  // Piece p's band grown by these crossings (grow_band) where its bulk is: by the store that keeps
  // it when it can, else here.
  void grow_piece(std::size_t p, std::vector<CapCrossing>&& crossings);
  // Marks the points of piece p's surface as some piece's (on arrival, while its global ids exist).
  void note_surface(std::size_t p);
  // A split piece's band, its Steiner maps, crossings and bulk's open cap faces into place.
  void install_band(std::size_t p, PieceBand&& split);
  // Whether every piece is split into band and bulk.
  bool all_split() const;
  // Piece p's bulk to the store, if there is one; and back.
  void store_bulk(std::size_t p);
  Block& bulk_here(std::size_t p);
  // Piece p's band part back from where it was split, when it was kept there.
  void band_here(std::size_t p);
  std::size_t band_part_tets(std::size_t p) const;
  // Before the assembly, with each bulk's share (by piece): each store numbers the bulks it keeps
  // while this one numbers its own.
  void number_bulks(const std::vector<BulkNumbering>& shares);
  // Piece p's bulk's tets and Steiner points, wherever it is.
  std::size_t bulk_tets(std::size_t p) const;
  std::size_t bulk_steiner_points(std::size_t p) const;
  // Welder::spread's step 1: each bulk's rows, those kept here moved into the mesh, and the links
  // of those (the others' left empty: their stores make them meanwhile); sets mesh.first_band_tet.
  std::vector<BlockLinks> spread_bulks(const AssemblyNumbering& numbering, SpreadMesh& mesh, StepClock& clock);
  // Welder::spread's step 4: the links of the bulks kept elsewhere, from their stores.
  void take_bulk_links(std::vector<BlockLinks>& links);
  // The stores keeping some bulk.
  std::set<BulkStore*> bulk_stores() const;
  // What the assembled mesh's numbering is made of (stages/assembly_numbering.hpp); the bands'
  // Steiner maps move into it.
  AssemblyPoints assembly_points();
  const SplitSurface& split_;
  const std::vector<PieceSurface>& pieces_;
  std::int32_t first_steiner_;  // provisional id of a piece's first Steiner point
  std::optional<BandSpec> split_on_arrival_;
  std::vector<Block> blocks_;  // per piece: its mesh, or once split its band
  std::vector<Block> bulks_;   // per piece, once split (in = true; empty arrays while stored)
  BulkStore* store_ = nullptr;
  struct StoredBulk {
    bool stored = false;
    std::size_t tets = 0, steiner_points = 0;
    BulkStore* store = nullptr;
    std::int32_t first_steiner = 0;  // the id of the piece's first Steiner point there
  };
  std::vector<StoredBulk> stored_;  // per piece
  struct BandElsewhere {  // a band part kept by the store of its bulk (PieceBand::band_kept)
    bool kept = false;
    std::size_t tets = 0;
    std::vector<std::int32_t> split_points;  // those its tets use, ascending
  };
  std::vector<BandElsewhere> band_elsewhere_;  // per piece
  std::vector<BulkStore*> share_stores_;       // the stores cut_kept_shares asked
  // Per split piece: the index in the piece of each of its band's Steiner points, and the place
  // in the piece of each band tet (to rejoin it, until finish_band).
  std::vector<std::vector<std::int32_t>> band_steiner_;
  std::vector<std::vector<std::int32_t>> band_tets_;
  std::vector<BandPartLinks> band_links_;  // per piece, from finish_band
  // Per piece: its band's links, made where it was split or grown (on its owner), until split_bands.
  std::vector<std::optional<BandPartLinks>> made_links_;
  // Bits, not bytes: they live from the pieces' arrival until the assembly.
  std::vector<bool> referenced_;        // per split point: some piece's surface has it
  std::vector<bool> band_used_before_;  // per point of the band mesh (weld_bands, band_points): a band tet uses it
  // Per piece split on arrival: the cap faces its band reached, and its bulk's open cap faces.
  std::vector<std::vector<CapCrossing>> crossings_;
  std::vector<std::vector<FaceKey>> bulk_cap_faces_;
};

// All at once: results ordered by piece index. Each piece's arrays are freed as soon as they
// are welded.
TetMesh weld(const SplitSurface& split, const std::vector<PieceSurface>& pieces, std::vector<PieceTetMesh>&& results);

}  // namespace partet
