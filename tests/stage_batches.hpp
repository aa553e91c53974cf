// The stages in one batch each, for the unit tests: the pipeline streams the same steps (each
// piece handed out as soon as it is closed), so partet itself has no use for these forms.
#pragma once
#include <string>
#include <vector>

#include "job/pipeline.hpp"
#include "partet/mesh_types.hpp"
#include "stages/closure.hpp"
#include "stages/merge.hpp"
#include "stages/piece.hpp"
#include "stages/seam_chain_band.hpp"
#include "stages/seam_healing.hpp"

namespace partet {

// All caps, in plane order.
std::vector<Cap> build_caps(SplitSurface& split, const std::vector<CutPlane>& planes, double density);
// All pieces (caps in plane order).
std::vector<PieceSurface> assemble_pieces(const SplitSurface& split, const std::vector<Cap>& caps);
// Partition, closure and assembly at once, as the first attempt of mesh_with_retries makes them.
PreparedPieces prepare_pieces(const SurfaceMesh& input, const MeshOptions& options);
// Closed, manifold, oriented, free of self-intersections and enclosing a positive volume.
void validate_surface(const SurfaceMesh& surface);

// An input's pieces meshed one after another in this process (no child processes), with the
// options that made them.
struct MeshedPieces {
  MeshOptions options;
  PreparedPieces prepared;
  std::vector<PieceTetMesh> results;
};
MeshedPieces mesh_pieces_in_batch(const SurfaceMesh& input, int k, double density = 1.0,
                                  const std::string& quality = "");
// The same in child processes, as partet meshes them (on real models TetGen may abort); throws
// the first piece's failure.
MeshedPieces mesh_pieces_isolated(const SurfaceMesh& input, int k);
// Takes every piece back from the welder (as a retry keeps the pieces that did not fail) and
// expects each as it was meshed: the same tets in the same order, neighbours, Steiner points.
void expect_pieces_come_back(Welder& welder, const std::vector<PieceTetMesh>& results);
// Meshes the regions of seam healing in this process, one after another.
RegionMesher regions_here(const MeshOptions& options);
// Heals `mesh` (a welded band, or the whole welded mesh) chain by chain in chain order, each chain
// cut out, healed alone and put back (seam_chain_band.hpp); counts the chains in `chains`. A chain
// that fails is a fatal test failure (the mesh is then as it was): call it in
// ASSERT_NO_FATAL_FAILURE.
void heal_chain_by_chain(TetMesh& mesh, const SurfaceMesh& input, const SplitSurface& split, const HealOptions& options,
                         const RegionMesher& mesher, std::size_t& chains);
// The pipeline's chains, in chain order, as their pieces' shares with their splits, ready to weld:
// the welder's bands split, the chains planned from their links, each piece's band part cut into
// its shares (seam_chain_band.hpp).
std::vector<ChainShares> gathered_chains(Welder& welder, const SurfaceMesh& input, const SplitSurface& split,
                                         const HealOptions& options);

}  // namespace partet
