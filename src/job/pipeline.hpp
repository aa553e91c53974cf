// The stages in order, on plain data. The MPI layer decides only where the pieces are meshed;
// everything else here runs on rank 0.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/stage_timer.hpp"
#include "mesher/tetgen_mesher.hpp"
#include "partet/mesh_types.hpp"
#include "runner/piece_runner.hpp"
#include "stages/closure.hpp"
#include "stages/merge.hpp"
#include "stages/partition.hpp"
#include "stages/piece.hpp"
#include "stages/polish.hpp"
#include "stages/seam_chain_band.hpp"
#include "stages/seam_healing.hpp"

namespace partet {

// Seam healing: whether the caps' interior points are removed too (the cut vertices on input
// edges always are). Automatic heals with a quality bound only: without one, TetGen's tets
// inside a piece span it, the stars of the cap points reach across the pieces, and re-meshing
// them costs more than meshing the pieces (bob.off refined to 2.74M faces, 16 pieces: 47 s of
// healing against 58 s of meshing), while the cap points improve those tets.
enum class Heal { automatic, on, off };

// What the cut planes balance between the pieces.
enum class Balance {
  cost,      // equal estimated TetGen cost: triangles, caps included (piece_cost.hpp)
  vertices,  // equal input vertex counts
};

struct MeshOptions {
  int pieces = 2;
  Balance balance = Balance::cost;
  double density = 0.25;  // chosen by scripts/bench/density_sweep.sh: best AMIPS avg and max on every model tried
  CutAxis axis = CutAxis::coordinate_near_pca;
  std::vector<int> plane_shifts;  // per cut plane, see choose_cut_planes
  int max_attempts = 40;          // partitions tried at most (see mesh_with_retries)
  Heal heal = Heal::automatic;
  bool polish = true;  // re-mesh the neighbourhoods of poor tets (with a quality bound only)
  // When TetGen cannot mesh the input without putting points on its surface, accept a mesh (of
  // the whole input as one piece) whose boundary splits some input triangles, instead of failing.
  bool allow_split_faces = false;
  // Non-empty: the paper's memory mode. Each piece's bulk (the tets seam healing never touches)
  // waits in a file in this directory from its arrival until the mesh is assembled.
  std::string scratch;
  // Leave the mesh where its parts are (MeshResult::spread) when the bulks stay on the ranks that
  // meshed them and the seams heal on the band alone: only formats written from the parts are
  // asked for (RootRun's may_spread).
  bool spread_output = false;
  // With spread_output: assemble the mesh after all when this process has at least this many
  // bytes available once the pieces are meshed (--check: a check in memory takes a third of the
  // time every rank takes to read the files back). 0: never.
  double assemble_if_available_bytes = 0;
  // With spread_output: keep the tets across the faces the parts share (16 bytes per face), which
  // only TetGen's .neigh file needs.
  bool spread_neighbours = false;
  // With spread_output: each seam chain healed on another rank stays there (HealOptions::
  // keep_healed), so rank 0 holds no band it did not heal; only when every format is written by
  // each rank from its own rows (the XDMF set).
  bool spread_band = false;
  TetgenOptions tetgen;
  RunOptions run;
};

// Whether these options heal the seams (remove the caps' interior points).
inline bool heals(const MeshOptions& options) {
  return options.heal == Heal::on || (options.heal == Heal::automatic && !options.tetgen.quality.empty());
}

// Whether these options polish the poor tets: only with a quality bound, since without one
// TetGen's tets are left as Delaunay made them on purpose and most are "poor".
inline bool polishes(const MeshOptions& options) { return options.polish && !options.tetgen.quality.empty(); }

// One attempt's partition and closure.
struct PreparedPieces {
  std::vector<CutPlane> planes;
  SplitSurface split;  // also holds the cap points
  std::vector<PieceSurface> pieces;
  std::int64_t cap_triangles = 0;
};

// One cut-plane move after a failure.
struct RetryRecord {
  int attempt = 0;          // the attempt that failed (0 = first)
  std::string reason;       // what failed
  std::vector<int> planes;  // planes moved for the next attempt
};

struct MeshResult {
  TetMesh mesh;  // empty when spread
  // With MeshOptions::spread_output, when it could be done: the mesh not assembled, its bulks
  // where they were meshed (spread_mesh.hpp).
  std::shared_ptr<SpreadMesh> spread;
  std::vector<CutPlane> planes;  // the cut planes used (around them: the seam zone)
  // The boundary faces, outward, in output numbering: the input triangles; with split faces the
  // whole input triangles first, then the parts of the split ones from split_faces_from on.
  // Empty when they are the input's triangles as they stand (every input vertex is used, so the
  // output keeps its numbering, and none is split): rank 0 then holds them once. Read them with
  // output_boundary.
  std::vector<Triangle> boundary_faces;
  std::size_t split_faces_from = SIZE_MAX;  // SIZE_MAX: no input triangle was split
  std::int64_t split_input_faces = 0;       // input triangles split by points on the surface
  std::int64_t surface_points_added = 0;    // the points TetGen put on the surface to split them
  SeamStats seam;
  PolishStats polish;
  std::int64_t cut_vertices_inserted = 0;
  std::int64_t cap_triangles = 0;
  int pieces = 0;                               // pieces actually used (fewer than asked when the model allows fewer)
  CutAxis axis = CutAxis::coordinate_near_pca;  // the direction of the cuts that worked
  std::vector<RetryRecord> retries;
  double merge_seconds_overlapped = 0;                // welding done while the last pieces were being meshed
  std::int64_t scratch_bulks = 0, scratch_bytes = 0;  // what waited in scratch files (MeshOptions::scratch)
  std::int64_t bulks_where_meshed = 0;  // pieces whose bulk stayed on the rank that meshed it until assembled
};

// The output's counts, whether assembled or spread.
inline std::size_t output_tet_count(const MeshResult& r) {
  return r.spread ? static_cast<std::size_t>(r.spread->tets) : r.mesh.tets.size();
}
inline std::size_t output_point_count(const MeshResult& r) {
  return r.spread ? static_cast<std::size_t>(r.spread->points) : r.mesh.points.size();
}

// The result's boundary faces in output numbering (see MeshResult::boundary_faces).
inline const std::vector<Triangle>& output_boundary(const MeshResult& result, const SurfaceMesh& input) {
  return result.boundary_faces.empty() ? input.triangles : result.boundary_faces;
}

// 3. Where the pieces of an attempt are meshed: this process, or the ranks of an MPI job. The
// pipeline submits each piece as soon as it is closed (so meshing overlaps the closure of the
// next ones), calls progress() between its own steps, and takes each outcome as it arrives (so
// welding overlaps the meshing of the last pieces).
class PieceScheduler {
 public:
  virtual ~PieceScheduler() = default;
  // The input's own checks may still be running elsewhere (on another rank, while this process
  // partitions): returns once they have passed (true if it waited for them), or throws their
  // InputError. Called before the first piece is submitted, and before any other error of the
  // run is reported, so the input's error comes first, as when it is checked before the rest.
  virtual bool confirm_input() { return false; }
  // A round meshes with these TetGen options (a retry may change them).
  virtual void begin_round(const TetgenOptions& tetgen) = 0;
  // The caps of the round's closure: share_caps hands over every border before the first cap
  // is needed (so other ranks may triangulate them meanwhile), cap(plane) returns each shape, in
  // plane order, built elsewhere or here. Throws the PartitionError of a cap that cannot close
  // its border.
  virtual void share_caps(std::vector<CapBorder> borders) { cap_borders_ = std::move(borders); }
  virtual CapShape cap(int plane) { return triangulate_cap(cap_borders_.at(static_cast<std::size_t>(plane))); }
  // In a round of pieces, before the first is submitted: the pieces meshed elsewhere are split
  // where they are meshed (split_where_meshed; spec.layers == 1), their outcomes bring only the
  // band, and the bulks stay there. Returns the store that gives a bulk back when the welder needs
  // it, or nullptr when every piece is meshed in this process (then nothing changes).
  virtual BulkStore* split_where_meshed(const BandSpec& /*spec*/) { return nullptr; }
  // The piece stays alive and unchanged until end_round returns.
  virtual void submit(const PieceSurface& piece) = 0;
  // Hands out work and takes in results without waiting.
  virtual void progress() {}
  // Waits for every submitted piece, handing each outcome to `arrived` as soon as it is in, with
  // its position in submission order. Must not throw from arrived (the other ranks wait in the
  // round).
  using Arrived = std::function<void(std::size_t position, PieceOutcome&& outcome)>;
  virtual void end_round(const Arrived& arrived) = 0;
  // Seam healing chain by chain (seam_chain_band.hpp), each chain healed whole on whichever rank
  // is free: false when this scheduler has no other rank (the chains then heal here, one after
  // another, their regions submitted as pieces).
  virtual bool heals_chains_on_ranks() const { return false; }
  // The rank to heal each chain (by its place in the order heal_chains hands them out; tets: each
  // one's size), decided before any is handed out, so that the ranks keeping the band parts send
  // each chain's shares straight there. Empty: every chain heals here.
  virtual std::vector<int> chain_ranks(const std::vector<std::size_t>& /*tets*/) { return {}; }
  // Heals `count` chains (on the ranks chain_ranks gave), chain i's split and the shares of the
  // band parts here gathered by cut_out(i) when it is handed out (the rank that heals it welds
  // it), its regions meshed with `tetgen`; returns each chain's outcome, by chain.
  using ChainCutter = std::function<ChainShares(std::size_t)>;
  virtual std::vector<HealedChain> heal_chains(std::size_t /*count*/, const ChainCutter& /*cut_out*/,
                                               const HealOptions& /*heal*/, const TetgenOptions& /*tetgen*/) {
    return {};
  }
  // The same, returning the outcomes in submission order.
  std::vector<PieceOutcome> end_round_all() {
    std::vector<PieceOutcome> outcomes;
    end_round([&](std::size_t position, PieceOutcome&& outcome) {
      if (outcomes.size() <= position) outcomes.resize(position + 1);
      outcomes[position] = std::move(outcome);
    });
    return outcomes;
  }

 protected:
  std::vector<CapBorder> cap_borders_;  // this round's, by plane
};

// Meshes every piece with the runner, one after another.
std::vector<PieceOutcome> mesh_pieces_here(const std::vector<PieceSurface>& pieces, const PieceRunner& runner);

// Meshes a round's pieces all at once, at its end, with a function (tests, one process).
using PieceMesher = std::function<std::vector<PieceOutcome>(const std::vector<PieceSurface>&, const TetgenOptions&)>;
class BatchScheduler : public PieceScheduler {
 public:
  explicit BatchScheduler(PieceMesher mesher) : mesher_(std::move(mesher)) {}
  void begin_round(const TetgenOptions& tetgen) override { tetgen_ = tetgen; }
  void submit(const PieceSurface& piece) override { pieces_.push_back(piece); }
  void end_round(const Arrived& arrived) override {
    std::vector<PieceOutcome> outcomes = mesher_(pieces_, tetgen_);
    pieces_.clear();
    for (std::size_t i = 0; i < outcomes.size(); ++i) arrived(i, std::move(outcomes[i]));
  }

 private:
  PieceMesher mesher_;
  TetgenOptions tetgen_;
  std::vector<PieceSurface> pieces_;
};

// 5. Heal the seams of the welded mesh, the regions around them meshed by the scheduler (in
// parallel).
MeshResult finish_mesh(const SurfaceMesh& input, const PreparedPieces& prepared, TetMesh&& welded,
                       const MeshOptions& options, PieceScheduler& scheduler, StageTimes* times = nullptr);
// 4. Splits the pieces into their band parts and bulks (seam_band.hpp), every piece in: the
// pieces' global ids go.
void split_bands(Welder& welder, PreparedPieces& prepared, const MeshOptions& options);
// 5. Heal the seams on the band alone, each chain welded from its pieces' band parts, then join
// the band to the bulks the welder kept. The split's points move into the band mesh.
MeshResult finish_mesh(const SurfaceMesh& input, PreparedPieces& prepared, Welder& welder, const MeshOptions& options,
                       PieceScheduler& scheduler, StageTimes* times = nullptr);

// Whether a mesh that may stay on its ranks is assembled after all, to be checked in memory
// (MeshOptions::assemble_if_available_bytes): when this process has the bytes it needs, and the
// mesh, about `tets` tets, has at most 2^30 (an assembled mesh numbers its tets in int32; a larger
// one is checked in its files by the ranks, whatever the memory).
bool assembles_to_check(double available_bytes, double needed_bytes, std::size_t tets);

// 4-5. Weld the pieces' meshes (consumed: each is freed once welded; ordered by piece index) and
// heal the seams, the regions meshed in this process, one after another.
MeshResult finish_mesh(const SurfaceMesh& input, const PreparedPieces& prepared, std::vector<PieceTetMesh>&& results,
                       const MeshOptions& options, StageTimes* times = nullptr);

// The whole pipeline with recovery: when a piece fails (a TetGen error or crash, a changed
// boundary) the planes bounding it move to other vertex gaps and the job is redone; when the
// cut-vertex removal fails, the planes of the failing region move; when partition or closure
// fails, all planes move. Pieces unchanged by the moves keep their earlier result. When the cuts
// keep failing, other directions are tried, then fewer pieces, then the whole input as one piece
// (src/job/retry_plan.hpp has the order). When that fails too, or after max_attempts partitions, the
// failure is thrown as MeshingError. Input and option errors are thrown at once. When TetGen alone
// cannot mesh the input keeping its triangles whole and options.allow_split_faces is set, the
// input is meshed as one piece with points allowed on its surface (MeshResult says how many
// triangles that split).
MeshResult mesh_with_retries(const SurfaceMesh& input, const MeshOptions& options, PieceScheduler& scheduler,
                             StageTimes* times = nullptr);
MeshResult mesh_with_retries(const SurfaceMesh& input, const MeshOptions& options, const PieceMesher& mesher,
                             StageTimes* times = nullptr);

// The whole pipeline in one process (pieces meshed one after another).
MeshResult mesh_surface(const SurfaceMesh& input, const MeshOptions& options, StageTimes* times = nullptr);

}  // namespace partet
