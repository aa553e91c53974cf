#include "stage_batches.hpp"

#include <gtest/gtest.h>

#include <string>

#include "partet/errors.hpp"
#include "stages/partition.hpp"
#include "stages/piece_cost.hpp"
#include "stages/seam_band.hpp"
#include "stages/seam_chain_band.hpp"
#include "stages/seam_chains.hpp"
#include "stages/validate.hpp"

namespace partet {

std::vector<Cap> build_caps(SplitSurface& split, const std::vector<CutPlane>& planes, double density) {
  CapBuilder builder(split, planes, density);
  std::vector<Cap> caps;
  for (std::size_t j = 0; j < planes.size(); ++j) caps.push_back(builder.build(static_cast<int>(j)));
  return caps;
}

std::vector<PieceSurface> assemble_pieces(const SplitSurface& split, const std::vector<Cap>& caps) {
  PieceAssembler assembler(split);
  std::vector<PieceSurface> pieces;
  const int k = split.piece_count;
  for (int p = 0; p < k; ++p)
    pieces.push_back(assembler.assemble(p, p > 0 ? &caps[p - 1] : nullptr, p + 1 < k ? &caps[p] : nullptr));
  return pieces;
}

PreparedPieces prepare_pieces(const SurfaceMesh& input, const MeshOptions& options) {
  PreparedPieces prepared;
  const std::vector<double> fractions =
      options.balance == Balance::cost && options.pieces > 1
          ? cost_balanced_fractions(input, cut_axis(input, options.axis), options.pieces, options.density)
          : std::vector<double>();
  prepared.planes = choose_cut_planes(input, options.pieces, options.axis, options.plane_shifts, fractions);
  prepared.split = split_at_planes(input, prepared.planes);
  const std::vector<Cap> caps = build_caps(prepared.split, prepared.planes, options.density);
  for (const Cap& cap : caps) prepared.cap_triangles += static_cast<std::int64_t>(cap.triangles.size());
  prepared.pieces = assemble_pieces(prepared.split, caps);
  return prepared;
}

void validate_surface(const SurfaceMesh& surface) {
  validate_topology(surface);
  check_no_self_intersections(surface);
  const double volume = enclosed_volume(surface);
  if (!(volume > 0))
    throw InputError(volume < 0 ? "input is inside out: normals point inwards (enclosed volume " +
                                      std::to_string(volume) + " < 0); flip the face orientation"
                                : std::string("input encloses no volume (enclosed volume 0)"));
}

MeshedPieces mesh_pieces_in_batch(const SurfaceMesh& input, int k, double density, const std::string& quality) {
  MeshedPieces s;
  s.options.pieces = k;
  s.options.density = density;
  s.options.tetgen.quality = quality;
  s.options.run.isolate = false;
  s.prepared = prepare_pieces(input, s.options);
  for (const auto& piece : s.prepared.pieces) s.results.push_back(tetrahedralize_piece(piece, s.options.tetgen));
  return s;
}

void expect_pieces_come_back(Welder& welder, const std::vector<PieceTetMesh>& results) {
  for (std::size_t p = 0; p < results.size(); ++p) {
    SCOPED_TRACE("piece " + std::to_string(p));
    const PieceTetMesh back = welder.take_back(static_cast<int>(p));
    EXPECT_EQ(back.index, results[p].index);
    EXPECT_EQ(back.surface_point_count, results[p].surface_point_count);
    EXPECT_EQ(back.mesh.tets, results[p].mesh.tets);
    EXPECT_EQ(back.mesh.neighbours, results[p].mesh.neighbours);
    EXPECT_EQ(back.mesh.steiner_points, results[p].mesh.steiner_points);
    EXPECT_FALSE(welder.has(static_cast<int>(p)));
  }
}

MeshedPieces mesh_pieces_isolated(const SurfaceMesh& input, int k) {
  MeshedPieces s;
  s.options.pieces = k;
  s.prepared = prepare_pieces(input, s.options);
  for (PieceOutcome& outcome : mesh_pieces_here(s.prepared.pieces, PieceRunner(s.options.tetgen, s.options.run))) {
    if (outcome.failure) throw MeshingError(*outcome.failure);
    s.results.push_back(std::move(outcome.result));
  }
  return s;
}

RegionMesher regions_here(const MeshOptions& options) {
  return [options](const std::vector<PieceSurface>& regions) {
    return mesh_pieces_here(regions, PieceRunner(options.tetgen, options.run));
  };
}

void heal_chain_by_chain(TetMesh& mesh, const SurfaceMesh& input, const SplitSurface& split, const HealOptions& options,
                         const RegionMesher& mesher, std::size_t& chains) {
  const std::vector<std::vector<int>> planes = seam_chain_planes(mesh, split, options);
  chains = planes.size();
  std::vector<ChainParts> parts = chain_parts(mesh, split, planes, options);
  std::vector<std::vector<std::int32_t>> chain_tets;
  std::vector<HealedChain> healed;
  for (std::size_t c = 0; c < planes.size(); ++c) {
    ChainBand chain = cut_out_chain(mesh, input, split, planes[c], std::move(parts[c]));
    chain_tets.push_back(chain.band_tets);
    healed.push_back(heal_chain(std::move(chain), options, mesher));
    ASSERT_FALSE(healed.back().failure) << "chain " << c << ": " << healed.back().failure->text();
  }
  put_back_chains(mesh, chain_tets, std::move(healed));
}

std::vector<ChainShares> gathered_chains(Welder& welder, const SurfaceMesh& input, const SplitSurface& split,
                                         const HealOptions& options) {
  welder.split_bands(seam_band_spec(split, options));
  const SeamChainPlan plan = seam_chain_plan(welder.take_band_links(), split, options);
  const std::vector<BandPartPlace> places = welder.band_part_places();
  const std::vector<std::vector<std::int32_t>> triangles = chain_split_triangles(split, plan.planes);
  std::vector<std::vector<ChainShare>> shares(plan.planes.size());
  for (std::size_t p = 0; p < places.size(); ++p) {
    const BandPartChains in_chains = band_part_chains(welder.band_part(p), plan.chain_of_part[p]);
    for (std::size_t i = 0; i < in_chains.chains.size(); ++i)
      shares.at(static_cast<std::size_t>(in_chains.chains[i]))
          .push_back(chain_share(welder.band_part(p), in_chains, i, places[p]));
  }
  std::vector<ChainShares> chains;
  for (std::size_t c = 0; c < plan.planes.size(); ++c) {
    const std::vector<std::int32_t> ids = welder.band_split_points(plan.pieces_in(static_cast<int>(c)));
    chains.push_back(chain_shares(std::move(shares[c]),
                                  chain_split(split, input, split.points, plan.planes[c], triangles[c], ids)));
  }
  return chains;
}

}  // namespace partet
