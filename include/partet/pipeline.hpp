// The stages in order, on plain data. The MPI layer decides only where the pieces are meshed;
// everything else here runs on rank 0.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "partet/closure.hpp"
#include "partet/cut_vertex_removal.hpp"
#include "partet/mesh_types.hpp"
#include "partet/partition.hpp"
#include "partet/piece.hpp"
#include "partet/piece_runner.hpp"
#include "partet/stage_timer.hpp"
#include "partet/tetgen_mesher.hpp"

namespace partet {

struct MeshOptions {
  int pieces = 2;
  double density = 0.25;  // chosen by scripts/density_sweep.sh: best AMIPS avg and max on every model tried
  CutAxis axis = CutAxis::coordinate_near_pca;
  std::vector<int> plane_shifts;  // per cut plane, see choose_cut_planes
  int max_attempts = 6;           // partitions tried before giving up, plus one per 4 pieces beyond the first
  TetgenOptions tetgen;
  RunOptions run;
};

struct PreparedPieces {
  SurfaceMesh input;
  std::vector<CutPlane> planes;
  SplitSurface split;  // also holds the cap points
  std::vector<PieceSurface> pieces;
  std::int64_t cap_triangles = 0;
};

// 1-2. Partition, surface closure and piece assembly.
// The input must already be validated.
PreparedPieces prepare_pieces(SurfaceMesh input, const MeshOptions& options, StageTimes* times = nullptr);

// One cut-plane move after a failure.
struct RetryRecord {
  int attempt = 0;          // the attempt that failed (0 = first)
  std::string reason;       // what failed
  std::vector<int> planes;  // planes moved for the next attempt
};

struct MeshResult {
  TetMesh mesh;
  std::vector<Triangle> boundary_faces;  // the input triangles, in output numbering
  CutVertexRemovalStats removal;
  std::int64_t cut_vertices_inserted = 0;
  std::int64_t cap_triangles = 0;
  int pieces = 0;  // pieces actually used (fewer than asked when the model allows fewer)
  std::vector<RetryRecord> retries;
};

// 3. Meshes all pieces (here, or on other ranks) and returns their outcomes in piece order.
using PieceMesher = std::function<std::vector<PieceOutcome>(const std::vector<PieceSurface>&)>;

// Meshes every piece with the runner, one after another.
std::vector<PieceOutcome> mesh_pieces_here(const std::vector<PieceSurface>& pieces, const PieceRunner& runner);

// 4-5. Weld the pieces' meshes (consumed: each is freed once welded, so rank 0 never holds the
// pieces and the merged mesh in full at once) and remove the cut vertices. results must be
// ordered by piece index.
MeshResult finish_mesh(const PreparedPieces& prepared, std::vector<PieceTetMesh>&& results, const MeshOptions& options,
                       StageTimes* times = nullptr);

// The whole pipeline with recovery: when a piece fails (a TetGen error or crash, a changed
// boundary) the planes bounding it move to other vertex gaps and the job is redone; when the
// cut-vertex removal fails, the planes of the failing region move; when partition or closure
// fails, all planes move. Pieces unchanged by the moves keep their earlier result. From the
// third attempt on the cap density is halved each time (0 on the last attempt). After
// max_attempts (+1 per 4 pieces) partitions the last failure is thrown as MeshingError.
// Input and option errors are thrown at once.
MeshResult mesh_with_retries(const SurfaceMesh& input, const MeshOptions& options, const PieceMesher& mesher,
                             StageTimes* times = nullptr);

// The whole pipeline in one process (pieces meshed one after another).
MeshResult mesh_surface(const SurfaceMesh& input, const MeshOptions& options, StageTimes* times = nullptr);

}  // namespace partet
