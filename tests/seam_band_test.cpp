// Seam bands: healing the bands alone, gathered from the pieces, gives the mesh that healing the
// whole welded mesh gives; the bands' layers cross the caps as a breadth-first search over the
// whole mesh does.
#include <gtest/gtest.h>

#include <algorithm>
#include <deque>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <string>
#include <vector>

#include "io/mesh_formats.hpp"
#include "io/read_surface.hpp"
#include "job/pipeline.hpp"
#include "runner/serialize.hpp"
#include "stage_batches.hpp"
#include "stage_helpers.hpp"
#include "test_support.hpp"
#include "stages/check.hpp"
#include "stages/generate.hpp"
#include "stages/kept_band_parts.hpp"
#include "stages/merge.hpp"
#include "stages/seam_band.hpp"
#include "stages/seam_chain_band.hpp"
#include "stages/seam_chains.hpp"
#include "stages/seam_healing.hpp"
#include "stages/spread_mesh.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

using namespace partet::test;

// The vertices healing removes: [first, end) of the split surface's ids.
std::pair<std::int32_t, std::int32_t> removed_ids(const SplitSurface& split, bool caps) {
  const std::int32_t first_cap = split.input_vertex_count + split.cut_vertex_count();
  return {split.input_vertex_count, first_cap + (caps ? static_cast<std::int32_t>(split.cap_point_plane.size()) : 0)};
}

BandSpec band_spec(const SplitSurface& split, bool caps, int layers) {
  const auto [first, end] = removed_ids(split, caps);
  return BandSpec{split.input_vertex_count, static_cast<std::int32_t>(split.points.size()), first, end, layers};
}

// The band path, in one process: weld the bands alone, heal them, assemble.
TetMesh heal_by_bands(const SurfaceMesh& input, const MeshedPieces& s, HealOptions options, std::size_t* band_tets = nullptr) {
  const SplitSurface& split = s.prepared.split;
  Welder welder(split, s.prepared.pieces);
  for (const auto& result : s.results) welder.add(PieceTetMesh(result));
  TetMesh band = welder.finish_band(split.points, band_spec(split, options.remove_cap_points, options.layers + 1));
  if (band_tets) *band_tets = band.tets.size();
  options.drop_points = false;
  heal_seams(band, input, split, options, regions_here(s.options));
  return welder.assemble(std::move(band));
}

// A piece's tets in global ids (Steiner point s as split point count + s), as the welder keeps them.
std::vector<Tet> global_tets(const PieceTetMesh& result, const PieceSurface& piece, std::int32_t split_points) {
  std::vector<Tet> tets = result.mesh.tets;
  for (auto& t : tets)
    for (auto& v : t)
      v = v < result.surface_point_count ? piece.global_ids[v] : split_points + (v - result.surface_point_count);
  return tets;
}

// Heals `input` in k pieces both ways, over the whole welded mesh and over the bands alone, and
// expects the same mesh: the same points in the same order, the same tets. (isolated: healing's
// regions are meshed in child processes, as partet meshes them: on real models TetGen may abort.)
void expect_bands_heal_as_the_whole(const SurfaceMesh& input, int k, const HealOptions& options, bool isolated = false) {
  const MeshedPieces s = isolated ? mesh_pieces_isolated(input, k) : mesh_pieces_in_batch(input, k);
  TetMesh whole = weld(s.prepared.split, s.prepared.pieces, std::vector<PieceTetMesh>(s.results));
  const std::size_t tets_welded = whole.tets.size();
  heal_seams(whole, input, s.prepared.split, options, regions_here(s.options));
  std::size_t band_tets = 0;
  const TetMesh banded = heal_by_bands(input, s, options, &band_tets);
  EXPECT_LE(band_tets, tets_welded);
  if (!options.remove_cap_points && k > 1) EXPECT_LT(band_tets, tets_welded);
  EXPECT_EQ(banded.points, whole.points);
  EXPECT_EQ(tet_set(banded.tets), tet_set(whole.tets));
  EXPECT_EQ(banded.neighbours, compute_neighbours(banded.tets));
  EXPECT_EQ(banded.piece.size(), banded.tets.size());
  const CheckReport report = check_mesh(input, banded);
  EXPECT_TRUE(report.ok());
}

TEST(SeamBand, HealingTheBandsGivesTheMeshHealingTheWholeGives) {
  for (const char* name : {"sphere", "torus", "genus3", "nested"})
    for (int k : {2, 3, 4})
      for (const bool caps : {false, true}) {
        SCOPED_TRACE(std::string(name) + " k=" + std::to_string(k) + (caps ? " caps healed" : " cut vertices only"));
        expect_bands_heal_as_the_whole(generate_surface(name, 1500), k, HealOptions{caps, 0});
      }
}

// The chains welded from the pieces' band parts (the pipeline's way), healed, and put into the
// band's points alone (Welder::band_points, add_healed_chains): the band is never welded. The
// chains find their links only when asked for them (`links`).
// With `kept`, every other chain stays where it healed (HealOptions::keep_healed): the band gets
// only what rank 0 is sent of it (kept_elsewhere, as kept on rank 1), and `kept` the chain itself.
TetMesh heal_chains_of_band_parts(Welder& welder, const SurfaceMesh& input, const SplitSurface& split,
                                  HealOptions options, const RegionMesher& mesher,
                                  std::vector<BandChainLinks>* links = nullptr,
                                  std::map<int, HealedChain>* kept = nullptr) {
  options.chain_links = links != nullptr;
  std::vector<HealedChain> healed;
  for (ChainShares& chain : gathered_chains(welder, input, split, options)) {
    healed.push_back(heal_chain(weld_chain(std::move(chain)), options, mesher));
    EXPECT_FALSE(healed.back().failure);
    const auto c = static_cast<int>(healed.size()) - 1;
    if (kept && c % 2 == 1) {
      (*kept)[c] = std::move(healed.back());
      healed.back() = kept_elsewhere(kept->at(c), 1, c);
    }
  }
  const std::size_t chains = healed.size();
  TetMesh band = welder.band_points(split.points);
  std::vector<BandChainLinks> made = add_healed_chains(band, std::move(healed), options.chain_links);
  EXPECT_EQ(made.size(), links ? chains : 0u);
  if (links) *links = std::move(made);
  return band;
}

// A chain cut out of the band heals there as it heals in the band (issue 22, item 2: a chain can
// heal on a rank of its own): the chains healed apart and put back give the band healed in one
// piece, point for point and tet for tet (both in order_band_tets' order), and it assembles into
// a valid mesh. So do the chains welded from the pieces' band parts, healed and put into the
// band's points alone, and the bulks then assemble with it into the same mesh. With a quality
// bound the regions add points and the band is deeper.
TEST(SeamBand, ChainsCutOutOfTheBandHealAsTheBand) {
  std::size_t most_chains = 0;
  for (const char* name : {"sphere", "torus", "genus3", "nested"})
    for (int k : {3, 5})
      for (const bool quality : {false, true})
        for (const bool caps : {false, true}) {
          if (quality && !caps) continue;  // (a quality bound heals the caps)
          SCOPED_TRACE(std::string(name) + " k=" + std::to_string(k) + (quality ? " quality" : "") +
                       (caps ? " caps healed" : ""));
          const SurfaceMesh input = generate_surface(name, 2000);
          const MeshedPieces s = mesh_pieces_in_batch(input, k, 1.0, quality ? "1.414" : "");
          const HealOptions options{caps, quality ? 2 : 0, false};
          const SplitSurface& split = s.prepared.split;
          Welder welder(split, s.prepared.pieces);
          for (const auto& result : s.results) welder.add(PieceTetMesh(result));
          TetMesh band = welder.finish_band(split.points, band_spec(split, caps, options.layers + 1));
          TetMesh by_chains = band;
          heal_seams(band, input, split, options, regions_here(s.options));
          order_band_tets(band);
          std::size_t chains = 0;
          ASSERT_NO_FATAL_FAILURE(heal_chain_by_chain(by_chains, input, split, options, regions_here(s.options), chains));
          most_chains = std::max(most_chains, chains);
          Welder of_parts(split, s.prepared.pieces);
          for (const auto& result : s.results) of_parts.add(PieceTetMesh(result));
          TetMesh from_parts = heal_chains_of_band_parts(of_parts, input, split, options, regions_here(s.options));
          // The chains put into the band's points alone keep their own order and neighbours: those
          // are the band's neighbours (no face between two chains), and in order_band_tets'
          // order it is the band healed in one piece.
          EXPECT_EQ(from_parts.neighbours, compute_neighbours(from_parts.tets, from_parts.points.size()));
          TetMesh from_parts_ordered = from_parts;
          order_band_tets(from_parts_ordered);
          for (const TetMesh* healed : {&by_chains, &from_parts_ordered}) {
            EXPECT_EQ(healed->points, band.points);
            EXPECT_EQ(healed->tets, band.tets);
            EXPECT_EQ(healed->neighbours, band.neighbours);
            EXPECT_EQ(healed->piece, band.piece);
          }
          const TetMesh assembled = welder.assemble(std::move(by_chains));
          EXPECT_TRUE(check_mesh(input, assembled).ok());
          TetMesh assembled_from_parts = of_parts.assemble(std::move(from_parts));
          EXPECT_TRUE(check_mesh(input, assembled_from_parts).ok());
          EXPECT_EQ(assembled_from_parts.points, assembled.points);
          EXPECT_EQ(assembled_from_parts.neighbours,
                    compute_neighbours(assembled_from_parts.tets, assembled_from_parts.points.size()));
          TetMesh ordered = assembled;
          order_band_tets(ordered), order_band_tets(assembled_from_parts);
          EXPECT_EQ(assembled_from_parts.tets, ordered.tets);
          EXPECT_EQ(assembled_from_parts.neighbours, ordered.neighbours);
        }
  EXPECT_GE(most_chains, 3u);
}

class SharedModels : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::is_directory(dir_)) GTEST_SKIP() << "no shared meshes at " << dir_;
  }
  std::string dir_ = PARTET_MESHES_DIR;
};

// The same on real models, CAD parts with slivers among them, where healing takes several rounds
// (a region that fails grows, and its second round sees the tets around it in another order
// than over the whole mesh): each region must reach TetGen the same whatever that order. A
// partition whose pieces TetGen refuses (partet would move its planes) is no case here; every
// model has at least four that mesh.
TEST_F(SharedModels, HealingTheBandsGivesTheMeshHealingTheWholeGives) {
  for (const char* name : {"part1", "lever", "hinge", "plate_holes", "t13_data", "spot_lowres", "nut", "tray_bottom",
                           "homer"}) {
    const SurfaceMesh input = read_surface(dir_ + "/" + name + ".off");
    int cases = 0;
    for (int k = 2; k <= 9; ++k) {
      SCOPED_TRACE(std::string(name) + " k=" + std::to_string(k));
      try {
        expect_bands_heal_as_the_whole(input, k, HealOptions{false, 0}, true);
        ++cases;
      } catch (const MeshingError& e) {
        EXPECT_GE(e.failure.piece, 0) << e.what();  // a piece refused, never a seam region
      }
    }
    EXPECT_GE(cases, 4) << name;
  }
}

// The bands of `name` in 4 pieces against a breadth-first search over the welded mesh.
void check_layers(const char* name, bool caps) {
  const SurfaceMesh input = generate_surface(name, 1500);
  const MeshedPieces s = mesh_pieces_in_batch(input, 4);
  const SplitSurface& split = s.prepared.split;
  for (int layers : {1, 3, 5}) {
    SCOPED_TRACE(std::string(name) + (caps ? " caps" : " cuts") + " layers " + std::to_string(layers));
    const auto [first, end] = removed_ids(split, caps);
    const BandSpec spec = band_spec(split, caps, layers);
    std::vector<std::vector<Tet>> tets;
    std::vector<const std::vector<Tet>*> tet_lists, neighbour_lists;
    for (std::size_t p = 0; p < s.results.size(); ++p)
      tets.push_back(global_tets(s.results[p], s.prepared.pieces[p], spec.split_point_count));
    for (std::size_t p = 0; p < s.results.size(); ++p) {
      tet_lists.push_back(&tets[p]);
      neighbour_lists.push_back(&s.results[p].mesh.neighbours);
    }
    const auto depths = mark_bands(tet_lists, neighbour_lists, spec);
    const TetMesh whole = weld(split, s.prepared.pieces, std::vector<PieceTetMesh>(s.results));
    std::vector<int> expected(whole.tets.size(), -1);
    std::vector<std::int32_t> queue;
    for (std::size_t t = 0; t < whole.tets.size(); ++t)
      for (auto v : whole.tets[t])
        if (v >= first && v < end) {
          expected[t] = 0;
          queue.push_back(static_cast<std::int32_t>(t));
          break;
        }
    for (std::size_t i = 0; i < queue.size(); ++i) {
      const auto t = queue[i];
      if (expected[t] == layers) continue;
      for (auto nb : whole.neighbours[t])
        if (nb >= 0 && expected[nb] < 0) expected[nb] = expected[t] + 1, queue.push_back(nb);
    }
    std::vector<int> found;
    std::size_t crossing_piece = 0;
    for (std::size_t p = 0; p < depths.size(); ++p)
      for (auto d : depths[p]) found.push_back(d);
    ASSERT_EQ(found, expected);
    // Some tet of a piece is in the band only through a neighbouring piece (it reaches no removed
    // vertex of its own piece within the layers): the trade across the caps was needed.
    for (std::size_t p = 0; p < depths.size(); ++p) {
      const auto own = mark_bands({tet_lists[p]}, {neighbour_lists[p]}, spec);
      if (own[0] != depths[p]) ++crossing_piece;
    }
    // (On the sphere and the torus cut at their cut vertices alone, with three layers or more.)
    const bool crosses = !caps && layers >= 3 && (std::string(name) == "sphere" || std::string(name) == "torus");
    if (crosses) EXPECT_GT(crossing_piece, 0u);
  }
}

// With a quality bound healing grows the stars by two layers, so the bands reach across the caps
// into the neighbouring pieces: the pieces trade the cap faces they reached until the bands match a
// breadth-first search over the welded mesh, depth for depth.
// A mesh left spread (Welder::spread) has, row for row, the points, tets, pieces, solids and
// neighbours (its blocks' own and those across their shared faces) of the assembled mesh: its blocks' rows, written where they are, make the assembled mesh's arrays.
// A .pvtu set's piece files made from a spread mesh's parts hold the assembled mesh's tets of
// their piece value in row order, their points numbered in order of first use with their ids
// and coordinates in the assembled mesh; rank 0 finds every point the band uses without the
// bulks.
namespace {
void expect_piece_files_as_assembled(const SpreadMesh& spread, const TetMesh& whole,
                                     const std::vector<std::int32_t>& regions) {
  std::vector<int> values(whole.piece.begin(), whole.piece.end());
  std::sort(values.begin(), values.end());
  values.erase(std::unique(values.begin(), values.end()), values.end());
  EXPECT_EQ(piece_values(spread), values);
  for (int piece : piece_values(spread)) {
    SCOPED_TRACE("piece " + std::to_string(piece));
    std::vector<GlobalTet> band;
    std::vector<std::int32_t> band_solid, bulk_solid, bulk_piece;
    band_tets_of(spread, piece, band, band_solid);
    const CompactTets compact = compact_tets(band);
    std::vector<TetsWithRegion> blocks;
    for (const SpreadBulk& bulk : spread.bulks)
      if (bulk.piece == piece) {
        bulk_columns(bulk.block, bulk, bulk_solid, bulk_piece);
        blocks.push_back({&bulk.block.tets, &bulk_solid, bulk.block.ids});
      }
    blocks.push_back({&compact.tets, &band_solid, compact.ids()});
    const VtuCells cells = piece_file_cells(piece, blocks);
    std::vector<Tet> expected, made;
    std::vector<std::int32_t> expected_region;
    for (std::size_t t = 0; t < whole.tets.size(); ++t)
      if (whole.piece[t] == piece) expected.push_back(whole.tets[t]), expected_region.push_back(regions[t]);
    std::int64_t next = 0;  // points numbered in order of first use
    for (std::size_t c = 0; c < cells.connectivity.size(); ++c) {
      const std::int64_t v = cells.connectivity[c];
      ASSERT_LE(v, next);
      if (v == next) ++next;
      if (c % 4 == 0) made.emplace_back();
      made.back()[c % 4] = static_cast<std::int32_t>(cells.global_ids[v]);
    }
    EXPECT_EQ(next, static_cast<std::int64_t>(cells.global_ids.size()));
    EXPECT_EQ(made, expected);
    EXPECT_EQ(cells.region, expected_region);
    EXPECT_EQ(cells.piece, std::vector<std::int32_t>(expected.size(), piece));
  }
  SpreadMesh rank0 = spread;  // as if every bulk were kept elsewhere
  for (SpreadBulk& bulk : rank0.bulks) bulk.here = false, bulk.block = TetBlock();
  for (const Tet& t : spread.band_tets)
    for (std::int64_t v : spread.band_ids()(t)) ASSERT_EQ(point_of(rank0, v), whole.points[v]);
}

// Each of these generated surfaces (1500 faces) cut into 3 and into 6 pieces and meshed, with the
// caps' points kept and healed: body(name, input, meshed pieces, caps healed).
template <class Body>
void for_each_small_case(std::initializer_list<const char*> names, const Body& body) {
  for (const char* name : names)
    for (int k : {3, 6})
      for (const bool caps : {false, true}) {
        SCOPED_TRACE(std::string(name) + " k=" + std::to_string(k) + (caps ? " caps healed" : ""));
        const SurfaceMesh input = generate_surface(name, 1500);
        const MeshedPieces s = mesh_pieces_in_batch(input, k);
        body(std::string(name), input, s, caps);
      }
}
}  // namespace

// A band made of healed chains is linked chain by chain, each chain a block with the links its
// healing rank found: the spread mesh is the one linked as one band, solids and faces across
// included.
TEST(SeamBand, ABandOfHealedChainsLinkedChainByChainIsLinkedAsOneBand) {
  std::size_t most_chains = 0, faces_across = 0;
  for_each_small_case({"torus", "two_spheres", "genus3"}, [&](const std::string&, const SurfaceMesh& input,
                                                               const MeshedPieces& s, bool caps) {
        const SplitSurface& split = s.prepared.split;
        HealOptions options{caps, 0};
        options.drop_points = false;
        Welder by_chains(split, s.prepared.pieces), as_one(split, s.prepared.pieces);
        for (const auto& result : s.results) by_chains.add(PieceTetMesh(result)), as_one.add(PieceTetMesh(result));
        std::vector<BandChainLinks> links;
        TetMesh a = heal_chains_of_band_parts(by_chains, input, split, options, regions_here(s.options), &links);
        TetMesh b = heal_chains_of_band_parts(as_one, input, split, options, regions_here(s.options));
        ASSERT_EQ(a.tets, b.tets);
        most_chains = std::max(most_chains, links.size());
        const SpreadMesh got = by_chains.spread(std::move(a), true, std::move(links));
        const SpreadMesh want = as_one.spread(std::move(b), true);
        EXPECT_EQ(got.band_tets, want.band_tets);
        EXPECT_EQ(got.band_point_ids, want.band_point_ids);
        EXPECT_EQ(got.band_solid, want.band_solid);
        ASSERT_EQ(got.band_across.size(), want.band_across.size());
        for (std::size_t i = 0; i < got.band_across.size(); ++i) {
          EXPECT_EQ(got.band_across[i].face, want.band_across[i].face);
          EXPECT_EQ(got.band_across[i].tet, want.band_across[i].tet);
        }
        ASSERT_EQ(got.bulks.size(), want.bulks.size());
        for (std::size_t p = 0; p < got.bulks.size(); ++p) {
          EXPECT_EQ(got.bulks[p].solid, want.bulks[p].solid);
          ASSERT_EQ(got.bulks[p].across.size(), want.bulks[p].across.size());
          for (std::size_t i = 0; i < got.bulks[p].across.size(); ++i) {
            EXPECT_EQ(got.bulks[p].across[i].face, want.bulks[p].across[i].face);
            EXPECT_EQ(got.bulks[p].across[i].tet, want.bulks[p].across[i].tet);
          }
        }
        faces_across += got.band_across.size();
      });
  EXPECT_GE(most_chains, 3u);
  EXPECT_GT(faces_across, 0u);  // (small pieces with their caps healed may be band alone)
}

// Healed chains kept by the rank that healed them (HealOptions::keep_healed; rank 0 gets their
// points, links and the points their tets use): the spread mesh is the one whose band rank 0
// holds whole, the same points, rows and solids; each chain here is its rows of that band, and
// each chain kept elsewhere, its tets through the ids rank 0 gives its rank, too.
TEST(SeamBand, HealedChainsKeptWhereTheyHealedAreTheirRowsOfTheBand) {
  std::size_t kept_chains = 0;
  for_each_small_case({"torus", "genus3"}, [&](const std::string&, const SurfaceMesh& input,
                                               const MeshedPieces& s, bool caps) {
        const SplitSurface& split = s.prepared.split;
        HealOptions options{caps, 0};
        options.drop_points = false;
        Welder kept_apart(split, s.prepared.pieces), all_here(split, s.prepared.pieces);
        for (const auto& result : s.results)
          kept_apart.add(PieceTetMesh(result)), all_here.add(PieceTetMesh(result));
        std::vector<BandChainLinks> links_apart, links_here;
        std::map<int, HealedChain> kept;
        const RegionMesher here = regions_here(s.options);
        TetMesh a = heal_chains_of_band_parts(kept_apart, input, split, options, here, &links_apart, &kept);
        TetMesh b = heal_chains_of_band_parts(all_here, input, split, options, here, &links_here);
        const SpreadMesh got = kept_apart.spread(std::move(a), false, std::move(links_apart));
        const SpreadMesh want = all_here.spread(std::move(b), false, std::move(links_here));
        EXPECT_EQ(got.points, want.points);
        EXPECT_EQ(got.tets, want.tets);
        EXPECT_EQ(got.split_points, want.split_points);
        EXPECT_EQ(got.healing_points, want.healing_points);
        EXPECT_EQ(got.first_band_tet, want.first_band_tet);
        for (std::size_t p = 0; p < got.bulks.size(); ++p) EXPECT_EQ(got.bulks[p].solid, want.bulks[p].solid);
        ASSERT_EQ(got.band_elsewhere(), !kept.empty());
        if (kept.empty()) return;
        std::int64_t row = got.first_band_tet;
        const PointIds here_ids = got.band_ids(), want_ids = want.band_ids();
        for (const BandRun& run : got.band_runs) {
          ASSERT_EQ(run.first_row, row);
          const bool elsewhere = run.rank != 0;
          const HealedChain* chain = elsewhere ? &kept.at(run.chain) : nullptr;
          if (elsewhere) ASSERT_EQ(static_cast<std::int64_t>(chain->tets.size()), run.tets);
          for (std::int64_t t = 0; t < run.tets; ++t, ++row) {
            const auto w = static_cast<std::size_t>(row - want.first_band_tet);
            const auto h = static_cast<std::size_t>(run.first_here + t);
            const GlobalTet tet =
                elsewhere ? PointIds{0, 0, run.point_ids.data()}(chain->tets[t]) : here_ids(got.band_tets[h]);
            EXPECT_EQ(tet, want_ids(want.band_tets[w]));
            EXPECT_EQ(elsewhere ? run.solid.at(chain->label[t]) : got.band_solid[h], want.band_solid[w]);
            EXPECT_EQ(elsewhere ? chain->piece[t] : got.band_piece[h], want.band_piece[w]);
          }
        }
        EXPECT_EQ(row, want.tets);
        kept_chains += kept.size();
      });
  EXPECT_GE(kept_chains, 4u);
}

TEST(SeamBand, ASpreadMeshHasTheAssembledMeshsRows) {
  for_each_small_case({"torus", "two_spheres", "nested"}, [&](const std::string& name, const SurfaceMesh& input,
                                                               const MeshedPieces& s, bool caps) {
        const SplitSurface& split = s.prepared.split;
        HealOptions options{caps, 0};
        options.drop_points = false;
        const BandSpec spec = band_spec(split, caps, 1);
        Welder assembling(split, s.prepared.pieces), spreading(split, s.prepared.pieces);
        for (const auto& result : s.results) assembling.add(PieceTetMesh(result)), spreading.add(PieceTetMesh(result));
        TetMesh a = assembling.finish_band(split.points, spec), b = spreading.finish_band(split.points, spec);
        heal_seams(a, input, split, options, regions_here(s.options));
        heal_seams(b, input, split, options, regions_here(s.options));
        const TetMesh whole = assembling.assemble(std::move(a));
        SpreadMesh spread = spreading.spread(std::move(b));
        ASSERT_EQ(spread.points, static_cast<std::int64_t>(whole.points.size()));
        ASSERT_EQ(spread.tets, static_cast<std::int64_t>(whole.tets.size()));
        std::vector<Point3> points(whole.points.size(), Point3{-1, -1, -1});
        std::vector<Tet> tets(whole.tets.size(), Tet{-1, -1, -1, -1});
        std::vector<std::int32_t> solid(whole.tets.size(), 0), piece(whole.tets.size(), -2);
        std::vector<NeighbourRow> neighbours(whole.tets.size(), NeighbourRow{-2, -2, -2, -2});
        // A block's neighbour rows in output ids, made in two parts as a writer streams them.
        const auto add_neighbours = [&](const std::vector<Tet>& own, std::int64_t first,
                                        const std::vector<FaceAcross>& across) {
          const std::size_t half = own.size() / 2;
          const std::vector<NeighbourRow> a = neighbour_rows(own, first, across, 0, half);
          const std::vector<NeighbourRow> b = neighbour_rows(own, first, across, half, own.size() - half);
          std::copy(a.begin(), a.end(), neighbours.begin() + first);
          std::copy(b.begin(), b.end(), neighbours.begin() + first + static_cast<std::int64_t>(half));
        };
        std::copy(spread.split_points.begin(), spread.split_points.end(), points.begin());
        std::copy(spread.healing_points.begin(), spread.healing_points.end(), points.begin() + spread.first_healing_point);
        for (const SpreadBulk& bulk : spread.bulks) {
          ASSERT_TRUE(bulk.here);  // no store: every bulk stayed in the welder
          ASSERT_EQ(static_cast<std::int64_t>(bulk.block.steiner_points.size()), bulk.points);
          std::copy(bulk.block.steiner_points.begin(), bulk.block.steiner_points.end(), points.begin() + bulk.first_point);
          // Compact ids: the split surface's points that stay, then the bulk's own from there.
          ASSERT_EQ(bulk.block.ids.from, static_cast<std::int32_t>(spread.split_points.size()));
          ASSERT_EQ(bulk.block.ids(bulk.block.ids.from), bulk.first_point);
          for (std::size_t t = 0; t < bulk.block.tets.size(); ++t)
            for (int j = 0; j < 4; ++j) {
              ASSERT_LT(bulk.block.tets[t][j], bulk.block.ids.from + bulk.points);
              tets[bulk.first_tet + t][j] = static_cast<std::int32_t>(bulk.block.ids(bulk.block.tets[t][j]));
            }
          std::vector<std::int32_t> bulk_solid, bulk_piece;
          bulk_columns(bulk.block, bulk, bulk_solid, bulk_piece);
          std::copy(bulk_solid.begin(), bulk_solid.end(), solid.begin() + bulk.first_tet);
          std::copy(bulk_piece.begin(), bulk_piece.end(), piece.begin() + bulk.first_tet);
          add_neighbours(bulk.block.neighbours, bulk.first_tet, bulk.across);
        }
        add_neighbours(spread.band_neighbours, spread.first_band_tet, spread.band_across);
        ASSERT_EQ(spread.band_point_ids.size(),
                  spread.band_steiner_points.size() + spread.healing_points.size());  // healing's are all used
        for (std::size_t t = 0; t < spread.band_tets.size(); ++t) {
          const GlobalTet g = spread.band_ids()(spread.band_tets[t]);
          for (int j = 0; j < 4; ++j) tets[spread.first_band_tet + t][j] = static_cast<std::int32_t>(g[j]);
        }
        std::copy(spread.band_solid.begin(), spread.band_solid.end(), solid.begin() + spread.first_band_tet);
        std::copy(spread.band_piece.begin(), spread.band_piece.end(), piece.begin() + spread.first_band_tet);
        EXPECT_EQ(points, whole.points);
        EXPECT_EQ(tets, whole.tets);
        EXPECT_EQ(piece, whole.piece);
        ASSERT_EQ(neighbours.size(), whole.neighbours.size());
        for (std::size_t t = 0; t < neighbours.size(); ++t)
          for (int j = 0; j < 4; ++j) ASSERT_EQ(neighbours[t][j], whole.neighbours[t][j]) << "tet " << t << " face " << j;
        const std::vector<std::int32_t> regions = region_of_tets(whole);
        EXPECT_EQ(solid, regions);
        if (name != "nested")  // (its shells' nesting decides)
          EXPECT_EQ(*std::max_element(regions.begin(), regions.end()), name == "two_spheres" ? 2 : 1);
        expect_piece_files_as_assembled(spread, whole, regions);
      });
}

// A piece file's points are numbered in order of first use across its blocks, whether its ids
// are compact (a bulk) or spread over the whole mesh (the seams' file).
TEST(SeamBand, APieceFilesPointsAreNumberedInOrderOfFirstUse) {
  for (const std::int32_t stride : {1, 100000}) {
    SCOPED_TRACE("stride " + std::to_string(stride));
    const std::vector<Tet> bulk{{7, 3, 9, 1}, {3, 9, 12, 7}}, band{{12, 40, 1, 2}, {2, 40, 41, 9}};
    std::vector<Tet> bulk_ids = bulk, band_ids = band;
    for (auto* tets : {&bulk_ids, &band_ids})
      for (Tet& t : *tets)
        for (std::int32_t& v : t) v *= stride;
    const std::vector<std::int32_t> bulk_region{1, 1}, band_region{1, 2};
    const VtuCells cells = piece_file_cells(4, {{&bulk_ids, &bulk_region}, {&band_ids, &band_region}});
    const std::vector<std::int64_t> first_use{7, 3, 9, 1, 12, 40, 2, 41};
    std::vector<std::int64_t> ids;
    for (std::int64_t v : first_use) ids.push_back(v * stride);
    EXPECT_EQ(cells.global_ids, ids);
    EXPECT_EQ(cells.connectivity, (std::vector<std::int64_t>{0, 1, 2, 3, 1, 2, 4, 0, 4, 5, 3, 6, 6, 5, 7, 2}));
    EXPECT_EQ(cells.offsets, (std::vector<std::int64_t>{4, 8, 12, 16}));
    EXPECT_EQ(cells.region, (std::vector<std::int32_t>{1, 1, 1, 2}));
    EXPECT_EQ(cells.piece, std::vector<std::int32_t>(4, 4));
  }
}

TEST(SeamBand, LayersCrossTheCapsAsOverTheWholeMesh) {
  for (const char* name : {"sphere", "torus", "genus3", "nested"})
    for (bool caps : {false, true}) check_layers(name, caps);
}

TEST(SeamBand, WithLayersTheBandsStillHealAsTheWhole) {
  const SurfaceMesh input = generate_surface("sphere", 4000);
  const MeshedPieces s = mesh_pieces_in_batch(input, 3, 1.0, "1.414");
  const HealOptions options{true, 2};
  TetMesh whole = weld(s.prepared.split, s.prepared.pieces, std::vector<PieceTetMesh>(s.results));
  heal_seams(whole, input, s.prepared.split, options, regions_here(s.options));
  const TetMesh banded = heal_by_bands(input, s, options);
  EXPECT_EQ(banded.points, whole.points);
  EXPECT_EQ(tet_set(banded.tets), tet_set(whole.tets));
  EXPECT_EQ(banded.neighbours, compute_neighbours(banded.tets));
  EXPECT_TRUE(check_mesh(input, banded).ok());
}

// Split into bands and bulks and put together again with nothing healed, the pieces give the
// welded mesh: the same points in the same order, the same tets, every neighbour joined.
TEST(SeamBand, BandsAndBulksAssembleIntoTheWeldedMesh) {
  for (const char* name : {"torus", "nested"})
    for (int layers : {1, 3}) {
      SCOPED_TRACE(std::string(name) + " layers " + std::to_string(layers));
      const SurfaceMesh input = generate_surface(name, 1500);
      const MeshedPieces s = mesh_pieces_in_batch(input, 3);
      const SplitSurface& split = s.prepared.split;
      const TetMesh whole = weld(split, s.prepared.pieces, std::vector<PieceTetMesh>(s.results));
      Welder welder(split, s.prepared.pieces);
      for (const auto& result : s.results) welder.add(PieceTetMesh(result));
      TetMesh band = welder.finish_band(split.points, band_spec(split, false, layers));
      EXPECT_GT(band.tets.size(), 0u);
      EXPECT_LT(band.tets.size(), whole.tets.size());
      const TetMesh again = welder.assemble(std::move(band));
      EXPECT_EQ(again.points, whole.points);
      EXPECT_EQ(tet_set(again.tets), tet_set(whole.tets));
      EXPECT_EQ(again.tets.size(), whole.tets.size());
      EXPECT_EQ(again.neighbours, compute_neighbours(again.tets));
      // Each tet keeps its piece.
      std::vector<std::pair<Tet, std::int32_t>> a, b;
      for (std::size_t t = 0; t < whole.tets.size(); ++t) a.push_back({whole.tets[t], whole.piece[t]});
      for (std::size_t t = 0; t < again.tets.size(); ++t) b.push_back({again.tets[t], again.piece[t]});
      std::sort(a.begin(), a.end());
      std::sort(b.begin(), b.end());
      EXPECT_EQ(a, b);
    }
}

// The bulks kept where their pieces were split (a worker rank, in the MPI layer).
class KeptWhereMeshed : public BulkStore {
 public:
  // numbers: as the MPI driver's owners, it numbers its bulks where they are (BulkStore::number);
  // grows: as they, it grows a band its neighbours' crossings reach with the bulk it keeps;
  // keeps_bands: as they, it keeps the band parts too (keep_band), grows them where they are and
  // cuts the chains' shares of them. What travels between the ranks goes through its messages.
  explicit KeptWhereMeshed(bool numbers = false, bool grows = false, bool keeps_bands = false)
      : numbers_(numbers), grows_(grows), keeps_bands_(keeps_bands) {}
  bool grows_bands() const override { return grows_; }
  PieceBand grow(BandToGrow&& sent) override {
    BandToGrow band = deserialize_band_to_grow(serialize_band_to_grow(sent));
    const int piece = band.index;
    if (band.band_kept) bands_.fill(band);
    PieceBand grown = grow_band(std::move(band), take(piece));
    keep(piece, std::move(grown.bulk));
    grown.bulk = TetBlock();
    if (keeps_bands_) bands_.keep(grown);
    ++grown_;
    return deserialize_grown_band(serialize_grown_band(grown));
  }
  // A piece's band part kept here, when this store keeps them.
  void keep_band(PieceBand& split) {
    if (keeps_bands_) bands_.keep(split);
  }
  PieceBand take_band(int piece) override {
    ++bands_taken_;
    return deserialize_grown_band(serialize_grown_band(bands_.take(piece)));
  }
  int bands_taken() const { return bands_taken_; }
  void cut_shares(const std::vector<BandPartPlan>& plans, const std::vector<int>& order,
                  const std::vector<int>& healers) override {
    EXPECT_TRUE(std::all_of(healers.begin(), healers.end(), [](int rank) { return rank == 0; }));  // (one process)
    cut_ = std::deque<std::pair<int, std::vector<ChainShare>>>();
    std::vector<BandPartPlan> plans_there;
    std::vector<int> order_there, healers_there;
    deserialize_share_plan(serialize_share_plan(plans, order, healers), plans_there, order_there, healers_there);
    bands_.cut_shares(plans_there, order_there, [&](int chain, std::vector<ChainShare>&& shares) {
      cut_.emplace_back(chain, deserialize_chain_shares(serialize_chain_shares(shares)));
    });
  }
  std::vector<ChainShare> shares(int chain) override {
    const auto it = std::find_if(cut_.begin(), cut_.end(), [&](const auto& c) { return c.first == chain; });
    if (it == cut_.end()) return {};
    EXPECT_TRUE(it == cut_.begin()) << "chain " << chain << " asked for out of order";
    std::vector<ChainShare> shares = std::move(it->second);
    cut_.erase(it);
    ++shares_given_;
    return shares;
  }
  int shares_given() const { return shares_given_; }
  int grown() const { return grown_; }
  void keep(int piece, TetBlock&& bulk) { bulks_[piece] = std::move(bulk); }
  bool put(int, const TetBlock&) override { return false; }
  void number(const std::vector<BulkShare>& shares) override {
    shares_ = shares.size();
    if (numbers_)
      for (const BulkShare& share : shares) number_bulk(bulks_.at(share.piece), share.numbering, share.first_steiner);
  }
  std::size_t shares() const { return shares_; }
  TetBlock take(int piece) override {
    TetBlock bulk = std::move(bulks_.at(piece));
    bulks_.erase(piece);
    return bulk;
  }
  std::size_t size() const { return bulks_.size(); }

 private:
  bool numbers_, grows_, keeps_bands_;
  KeptBandParts bands_;
  std::deque<std::pair<int, std::vector<ChainShare>>> cut_;  // by chain, in the order given
  int bands_taken_ = 0, shares_given_ = 0;
  int grown_ = 0;
  std::size_t shares_ = 0;
  std::map<int, TetBlock> bulks_;
};

// Copies of the bulks as they went to the store, and the bulks given back on demand.
class KeptCopies : public BulkStore {
 public:
  bool put(int piece, const TetBlock& bulk) override {
    bulks_[piece] = bulk;
    return true;
  }
  TetBlock take(int piece) override {
    ++taken_;
    return bulks_.at(piece);
  }
  const TetBlock& at(int piece) const { return bulks_.at(piece); }
  int taken() const { return taken_; }

 private:
  std::map<int, TetBlock> bulks_;
  int taken_ = 0;
};

// The numbering is made from the healed band alone, and each bulk numbered with its own share of
// it, away from the rest, is its piece's part of the assembled mesh: its tets where the assembly
// puts them, its Steiner points at their ids. Healed with and without the caps' points.
TEST(SeamBand, EachBulkNumberedWithItsShareIsItsPartOfTheAssembledMesh) {
  for (const char* name : {"torus", "nested", "genus3"})
    for (const bool caps : {false, true}) {
      SCOPED_TRACE(std::string(name) + (caps ? " caps healed" : " cut vertices only"));
      const SurfaceMesh input = generate_surface(name, 1500);
      const MeshedPieces s = mesh_pieces_in_batch(input, 4);
      const SplitSurface& split = s.prepared.split;
      const BandSpec spec = band_spec(split, caps, 1);
      Welder welder(split, s.prepared.pieces);
      KeptCopies store;
      welder.split_on_arrival(spec);
      welder.keep_bulks_in(store);
      for (const auto& result : s.results) welder.add(PieceTetMesh(result));
      TetMesh band = welder.finish_band(split.points, spec);
      heal_seams(band, input, split, HealOptions{caps, 0, false}, regions_here(s.options));
      const AssemblyNumbering numbering = welder.numbering(band);
      EXPECT_EQ(store.taken(), 0);  // no bulk came back for it
      std::vector<BulkNumbering> shares;
      for (std::size_t p = 0; p < s.results.size(); ++p) shares.push_back(numbering.for_bulk(p));
      const TetMesh mesh = welder.assemble(std::move(band), numbering);
      ASSERT_EQ(mesh.points.size(), static_cast<std::size_t>(numbering.point_count()));
      std::size_t first = 0, dropped = 0;
      for (std::size_t p = 0; p < shares.size(); ++p) {
        const TetBlock& bulk = store.at(static_cast<int>(p));
        for (std::size_t t = 0; t < bulk.tets.size(); ++t) {
          Tet numbered = bulk.tets[t];  // compact ids, then the mesh's
          for (auto& v : numbered) v = static_cast<std::int32_t>(shares[p].ids()(shares[p](v)));
          ASSERT_EQ(numbered, mesh.tets[first + t]) << "piece " << p << " tet " << t;
        }
        first += bulk.tets.size();
        for (std::size_t i = 0; i < bulk.steiner_points.size(); ++i) {
          const std::int32_t compact = shares[p](static_cast<std::int32_t>(split.points.size() + i));
          if (compact < 0)
            ++dropped;
          else
            EXPECT_EQ(mesh.points[shares[p].ids()(compact)], bulk.steiner_points[i]);
        }
      }
      EXPECT_LT(first, mesh.tets.size());  // the band follows
      EXPECT_EQ(mesh.neighbours, compute_neighbours(mesh.tets));
      EXPECT_TRUE(check_mesh(input, mesh).ok());
      if (!caps) EXPECT_EQ(dropped, 0u);  // only cut vertices go then, and they are split points
    }
}

// The bulks kept where their pieces were meshed (their Steiner points numbered from 2^30 there)
// and numbered there with their shares, all before the first comes back, give the same assembled
// mesh as the bulks numbered by the welder as they come back; with healed caps, whose points go.
TEST(SeamBand, BulksNumberedWhereTheyAreKeptGiveTheSameMesh) {
  for (const char* name : {"torus", "nested", "genus3"})
    for (const bool caps : {false, true}) {
      SCOPED_TRACE(std::string(name) + (caps ? " caps healed" : " cut vertices only"));
      const SurfaceMesh input = generate_surface(name, 1500);
      const MeshedPieces s = mesh_pieces_in_batch(input, 5);
      const SplitSurface& split = s.prepared.split;
      const BandSpec spec = band_spec(split, caps, 1);
      BandSpec there = spec;
      there.split_point_count = 1 << 30;
      if (caps) there.end_removed = 1 << 30;
      std::vector<TetMesh> meshes;
      for (const bool numbers_there : {false, true}) {
        KeptWhereMeshed kept(numbers_there);
        Welder welder(split, s.prepared.pieces);
        welder.split_on_arrival(spec);
        for (std::size_t p = 0; p < s.results.size(); ++p) {
          if (p == 2) {  // one piece split by the welder, its bulk kept and numbered there
            welder.add(PieceTetMesh(s.results[p]));
            continue;
          }
          PieceBand band = split_where_meshed(PieceTetMesh(s.results[p]), s.prepared.pieces[p].global_ids, there);
          kept.keep(band.index, std::move(band.bulk));
          welder.add_split(std::move(band), kept);
        }
        TetMesh band = welder.finish_band(split.points, spec);
        heal_seams(band, input, split, HealOptions{caps, 0, false}, regions_here(s.options));
        meshes.push_back(welder.assemble(std::move(band)));
        EXPECT_EQ(kept.shares(), s.results.size() - 1);  // a share for every bulk it kept
        EXPECT_EQ(kept.size(), 0u);                        // and every one came back
      }
      expect_same_tet_mesh(meshes[1], meshes[0]);
      EXPECT_EQ(meshes[1].piece, meshes[0].piece);
      EXPECT_EQ(meshes[1].neighbours, meshes[0].neighbours);
      EXPECT_TRUE(check_mesh(input, meshes[1]).ok());
    }
}

// Split as each piece arrives (one layer: a piece alone decides its band), the pieces give the same
// band mesh as split all at once at the end, and the same mesh when joined again; so do the pieces
// split where they were meshed, their Steiner points numbered from 2^30 there (the closure may
// still add cap points) and their bulks kept there, whether the bulks a neighbour's crossing
// reaches come back to grow their bands (`elsewhere`) or the bands grow where the bulks are kept
// (`grown_there`, as on the MPI driver's owners: no bulk comes back before the assembly).
TEST(SeamBand, PiecesSplitOnArrivalGiveTheBandsSplitAtTheEnd) {
  int grown_there_total = 0;
  for (const char* name : {"torus", "nested"})
    for (const int k : {3, 12})  // 12: thin pieces, whose tets reach from one cap to the other
      for (const bool caps : {false, true}) {
        SCOPED_TRACE(std::string(name) + " k=" + std::to_string(k) + (caps ? " caps" : " cuts"));
        const SurfaceMesh input = generate_surface(name, 1500);
        const MeshedPieces s = mesh_pieces_in_batch(input, k);
        const SplitSurface& split = s.prepared.split;
        const BandSpec spec = band_spec(split, caps, 1);
        BandSpec there = spec;
        there.split_point_count = 1 << 30;
        if (caps) there.end_removed = 1 << 30;
        KeptWhereMeshed kept, kept_growing(false, true);
        Welder at_end(split, s.prepared.pieces), on_arrival(split, s.prepared.pieces), elsewhere(split, s.prepared.pieces);
        Welder grown_there(split, s.prepared.pieces);
        on_arrival.split_on_arrival(spec), elsewhere.split_on_arrival(spec), grown_there.split_on_arrival(spec);
        for (std::size_t p = 0; p < s.results.size(); ++p) {
          at_end.add(PieceTetMesh(s.results[p])), on_arrival.add(PieceTetMesh(s.results[p]));
          for (auto [welder, store] : {std::pair{&elsewhere, &kept}, std::pair{&grown_there, &kept_growing}}) {
            PieceBand band = split_where_meshed(PieceTetMesh(s.results[p]), s.prepared.pieces[p].global_ids, there);
            store->keep(band.index, std::move(band.bulk));
            welder->add_split(std::move(band), *store);
          }
        }
        TetMesh a = at_end.finish_band(split.points, spec), b = on_arrival.finish_band(split.points, spec);
        TetMesh c = elsewhere.finish_band(split.points, spec), d = grown_there.finish_band(split.points, spec);
        EXPECT_GT(a.tets.size(), 0u);
        for (const TetMesh* band : {&b, &c, &d}) {
          expect_same_tet_mesh(*band, a);
          EXPECT_EQ(band->piece, a.piece);
          EXPECT_EQ(band->neighbours, a.neighbours);
        }
        EXPECT_EQ(on_arrival.bulk_tet_count(), at_end.bulk_tet_count());
        EXPECT_EQ(elsewhere.bulk_tet_count(), at_end.bulk_tet_count());
        EXPECT_EQ(grown_there.bulk_tet_count(), at_end.bulk_tet_count());
        EXPECT_EQ(kept_growing.size(), s.results.size());  // no bulk came back to grow a band
        grown_there_total += kept_growing.grown();
        const TetMesh whole = at_end.assemble(std::move(a));
        expect_same_tet_mesh(on_arrival.assemble(std::move(b)), whole);
        expect_same_tet_mesh(elsewhere.assemble(std::move(c)), whole);
        const TetMesh assembled = grown_there.assemble(std::move(d));
        expect_same_tet_mesh(assembled, whole);
        EXPECT_EQ(assembled.neighbours, whole.neighbours);
        EXPECT_EQ(kept.size(), 0u);  // every bulk came back
        EXPECT_EQ(kept_growing.size(), 0u);
      }
  EXPECT_GT(grown_there_total, 0);  // thin pieces: some bands grew where their bulks were kept
}

// Each piece split where it was meshed (one layer), its Steiner points numbered from 2^30 there
// and its bulk kept there by `kept` (whose bands grow there), added to `welder`.
// (every_other_here: the even pieces are added whole and split on arrival, as rank 0's own.)
void add_split_where_meshed(Welder& welder, KeptWhereMeshed& kept, const MeshedPieces& s, const BandSpec& spec,
                            bool caps, bool every_other_here = false) {
  BandSpec there = spec;
  there.split_point_count = 1 << 30;
  if (caps) there.end_removed = 1 << 30;
  welder.split_on_arrival(spec);
  for (std::size_t p = 0; p < s.results.size(); ++p) {
    if (every_other_here && p % 2 == 0) {
      welder.add(PieceTetMesh(s.results[p]));
      continue;
    }
    PieceBand piece = split_where_meshed(PieceTetMesh(s.results[p]), s.prepared.pieces[p].global_ids, there);
    kept.keep(piece.index, std::move(piece.bulk));
    kept.keep_band(piece);
    welder.add_split(std::move(piece), kept);
  }
}

// The chains can be found from what each piece's band part tells (its parts, the vertices to
// remove in each, its open cap faces: band_part_links, issue 22) without the welded band: the
// same chains as on the welded band and as on the whole welded mesh, whether the pieces were
// split at the end, or where they were meshed with their bands grown there. Thin pieces (k=12)
// chain neighbouring cuts; healed caps chain the cuts of wide pieces.
TEST(SeamBand, TheBandPartsLinksGiveTheChainsOfTheWeldedBand) {
  std::size_t most_chains = 0, longest_chain = 0;
  for (const char* name : {"sphere", "torus", "genus3", "nested"})
    for (const int k : {3, 5, 12})
      for (const int layers : {0, 2})
        for (const bool caps : {false, true}) {
          if (layers > 0 && !caps) continue;  // (a quality bound heals the caps)
          SCOPED_TRACE(std::string(name) + " k=" + std::to_string(k) + " layers=" + std::to_string(layers) +
                       (caps ? " caps" : " cuts"));
          const SurfaceMesh input = generate_surface(name, 1500);
          const MeshedPieces s = mesh_pieces_in_batch(input, k);
          const SplitSurface& split = s.prepared.split;
          const HealOptions options{caps, layers, false};
          const BandSpec spec = band_spec(split, caps, layers + 1);
          const TetMesh whole = weld(split, s.prepared.pieces, std::vector<PieceTetMesh>(s.results));
          const std::vector<std::vector<int>> chains = seam_chain_planes(whole, split, options);
          Welder at_end(split, s.prepared.pieces);
          for (const auto& result : s.results) at_end.add(PieceTetMesh(result));
          const TetMesh band = at_end.finish_band(split.points, spec);
          EXPECT_EQ(seam_chain_planes(band, split, options), chains);
          EXPECT_EQ(seam_chain_plan(at_end.take_band_links(), split, options).planes, chains);
          if (layers == 0) {  // one layer: split where meshed, grown where kept
            KeptWhereMeshed kept(false, true);
            Welder grown_there(split, s.prepared.pieces);
            add_split_where_meshed(grown_there, kept, s, spec, caps);
            grown_there.finish_band(split.points, spec);
            EXPECT_EQ(seam_chain_plan(grown_there.take_band_links(), split, options).planes, chains);
          }
          most_chains = std::max(most_chains, chains.size());
          for (const auto& chain : chains) longest_chain = std::max(longest_chain, chain.size());
        }
  EXPECT_GE(most_chains, 5u);
  EXPECT_GE(longest_chain, 3u);
}

void expect_same_chain(ChainBand&& welded, const ChainBand& cut) {
  EXPECT_EQ(welded.planes, cut.planes);
  EXPECT_EQ(welded.global_ids, cut.global_ids);
  EXPECT_EQ(welded.band_tets, cut.band_tets);
  EXPECT_EQ(welded.mesh.points, cut.mesh.points);
  EXPECT_EQ(welded.mesh.tets, cut.mesh.tets);
  EXPECT_EQ(welded.mesh.neighbours, cut.mesh.neighbours);
  EXPECT_EQ(welded.mesh.piece, cut.mesh.piece);
  EXPECT_EQ(welded.input.triangles, cut.input.triangles);
  EXPECT_EQ(welded.split.input_vertex_count, cut.split.input_vertex_count);
  EXPECT_EQ(welded.split.cut_vertex_plane, cut.split.cut_vertex_plane);
  EXPECT_EQ(welded.split.cap_point_plane, cut.split.cap_point_plane);
  EXPECT_EQ(welded.split.triangles, cut.split.triangles);
  EXPECT_EQ(welded.split.parent, cut.split.parent);
}

// Each chain can be welded from its pieces' shares of it (chain_share: each piece's band part
// cut by the chains of its parts, as the links plan them; issue 22, item 2: the owners of the
// band parts can send these to the rank that heals the chain, which welds it): the chain is the
// one cut out of the welded band, point for point and tet for tet, here or after travelling in a
// chain task with its split (chain_split, made from the pieces' band parts' split points, without
// the chain's tets, and the only source of those points' coordinates: a split without one of them
// cannot weld it), whatever the order of the shares, whether
// the pieces were split at the end or where they were meshed with their bands grown there (their
// links made there too, as they are made from the band part here); and the chains hold every tet
// of the band.
TEST(SeamBand, AChainWeldedFromItsPiecesSharesIsTheChainCutOutOfTheBand) {
  std::size_t most_shares = 0;
  for (const char* name : {"sphere", "torus", "genus3", "nested"})
    for (const int k : {3, 12})
      for (const int layers : {0, 2})
        for (const bool caps : {false, true})
          for (const bool where_meshed : {false, true}) {
            if ((layers > 0 && !caps) || (where_meshed && layers > 0)) continue;
            SCOPED_TRACE(std::string(name) + " k=" + std::to_string(k) + " layers=" + std::to_string(layers) +
                         (caps ? " caps" : " cuts") + (where_meshed ? " split where meshed" : ""));
            const SurfaceMesh input = generate_surface(name, 1500);
            const MeshedPieces s = mesh_pieces_in_batch(input, k);
            const SplitSurface& split = s.prepared.split;
            const HealOptions options{caps, layers, false};
            const BandSpec spec = band_spec(split, caps, layers + 1);
            KeptWhereMeshed kept(false, true);
            Welder welder(split, s.prepared.pieces);
            if (where_meshed) {
              add_split_where_meshed(welder, kept, s, spec, caps);
            } else {
              for (const auto& result : s.results) welder.add(PieceTetMesh(result));
            }
            welder.split_bands(spec);
            const std::vector<BandPartLinks> links = welder.take_band_links();
            const SeamChainPlan plan = seam_chain_plan(links, split, options);
            const std::vector<BandPartPlace> places = welder.band_part_places();
            const std::vector<std::vector<std::int32_t>> triangles = chain_split_triangles(split, plan.planes);
            for (std::size_t p = 0; p < places.size(); ++p) {  // made where split (and grown) as here
              const BandPartLinks here = band_part_links(welder.band_part(p), spec);
              EXPECT_EQ(links[p].removed, here.removed);
              EXPECT_TRUE(links[p].cap_faces == here.cap_faces);
            }
            std::vector<std::vector<ChainShare>> shares(plan.planes.size());
            for (std::size_t p = 0; p < places.size(); ++p) {
              const BandPartChains in_chains = band_part_chains(welder.band_part(p), plan.chain_of_part[p]);
              for (std::size_t i = 0; i < in_chains.chains.size(); ++i) {
                const int c = in_chains.chains[i];
                shares.at(static_cast<std::size_t>(c))
                    .push_back(chain_share(welder.band_part(p), in_chains, i, places[p]));
              }
            }
            std::vector<ChainSplit> splits;  // made before the band parts are welded, as rank 0 makes them
            for (std::size_t c = 0; c < plan.planes.size(); ++c)
              splits.push_back(chain_split(split, input, split.points, plan.planes[c], triangles[c],
                                           welder.band_split_points(plan.pieces_in(static_cast<int>(c)))));
            TetMesh band = welder.weld_bands(split.points);
            std::vector<ChainParts> parts = chain_parts(band, split, plan.planes, options);
            std::size_t in_chains = 0;
            for (std::size_t c = 0; c < plan.planes.size(); ++c) {
              most_shares = std::max(most_shares, shares[c].size());
              std::reverse(shares[c].begin(), shares[c].end());  // (any order)
              const ChainBand cut = cut_out_chain(band, input, split, plan.planes[c], std::move(parts[c]));
              ChainShares gathered = chain_shares(std::move(shares[c]), std::move(splits[c]));
              EXPECT_EQ(band_tets_of(gathered), cut.band_tets);
              if (c == 0) {  // a split without one of the chain's points cannot weld it
                ChainShares lacking = gathered;
                std::vector<std::int32_t>& ids = lacking.split.point_ids;
                const auto at = std::lower_bound(ids.begin(), ids.end(), cut.global_ids.front());
                ASSERT_TRUE(at != ids.end() && *at == cut.global_ids.front());
                lacking.split.points.erase(lacking.split.points.begin() + (at - ids.begin()));
                ids.erase(at);
                EXPECT_THROW(weld_chain(std::move(lacking)), InternalError);
              }
              // Welded here, and where a chain task takes it (another rank): the same chain.
              ChainTask task{static_cast<std::int32_t>(c), gathered, options, TetgenOptions()};
              std::reverse(task.chain.shares.begin(), task.chain.shares.end());  // (a rank appends those it takes)
              expect_same_chain(weld_chain(std::move(gathered)), cut);
              expect_same_chain(weld_chain(deserialize_chain_task(serialize_chain_task(task)).chain), cut);
              in_chains += cut.band_tets.size();
            }
            EXPECT_EQ(in_chains, band.tets.size());
          }
  EXPECT_GE(most_shares, 3u);  // a chain over several pieces
}

// On the generated inputs the parts that meet across a cap also share a cut's vertices, so the
// joins across caps seldom decide there; here they do: two pieces' parts hold the vertices of
// different groups and meet only through a cap face, which joins their chains.
TEST(SeamBand, BandPartsMeetingAcrossACapJoinTheirChains) {
  const FaceKey cap_face(Triangle{20, 21, 22}), other(Triangle{20, 21, 23});
  const std::int32_t first = 10;
  const std::vector<int> group{0, 0, 1, 1, 2};  // of vertices 10..14
  BandPartLinks lower, upper;
  lower.removed = {{10, 11}, {14}};
  lower.cap_faces = {{cap_face, 0}};
  upper.removed = {{12, 13}};
  upper.cap_faces = {{cap_face, 0}};
  SeamChains chains = seam_chains({lower, upper}, first, group, 3);
  EXPECT_EQ(chains.count, 2);
  EXPECT_EQ(chains.of_group, (std::vector<int>{0, 0, 1}));
  upper.cap_faces = {{other, 0}};  // no face in common
  chains = seam_chains({lower, upper}, first, group, 3);
  EXPECT_EQ(chains.count, 3);
  EXPECT_EQ(chains.of_group, (std::vector<int>{0, 1, 2}));
  // A part with no vertex to remove links the parts on either side of it.
  BandPartLinks middle;
  middle.removed = {{}};
  middle.cap_faces = {{other, 0}, {cap_face, 0}};
  std::sort(middle.cap_faces.begin(), middle.cap_faces.end());
  lower.cap_faces = {{cap_face, 0}};
  chains = seam_chains({lower, middle, upper}, first, group, 3);
  EXPECT_EQ(chains.of_group, (std::vector<int>{0, 0, 1}));
}

// A retry keeps the pieces that did not fail: a piece split where it was meshed comes back whole.
TEST(SeamBand, APieceSplitWhereMeshedComesBackAsItWasMeshed) {
  const SurfaceMesh input = generate_surface("genus3", 1500);
  const MeshedPieces s = mesh_pieces_in_batch(input, 4);
  const SplitSurface& split = s.prepared.split;
  BandSpec there = band_spec(split, false, 1);
  there.split_point_count = 1 << 30;
  KeptWhereMeshed kept;
  Welder welder(split, s.prepared.pieces);
  welder.split_on_arrival(band_spec(split, false, 1));
  for (std::size_t p = 0; p < s.results.size(); ++p) {
    PieceBand band = split_where_meshed(PieceTetMesh(s.results[p]), s.prepared.pieces[p].global_ids, there);
    kept.keep(band.index, std::move(band.bulk));
    welder.add_split(std::move(band), kept);
  }
  expect_pieces_come_back(welder, s.results);
  EXPECT_EQ(kept.size(), 0u);
}

// A retry keeps the results of the pieces that did not fail: split on arrival, each comes back
// exactly as it was added (the same tets in the same order, neighbours, Steiner points).
TEST(SeamBand, APieceSplitOnArrivalComesBackAsItWasAdded) {
  const SurfaceMesh input = generate_surface("genus3", 1500);
  const MeshedPieces s = mesh_pieces_in_batch(input, 4);
  Welder welder(s.prepared.split, s.prepared.pieces);
  welder.split_on_arrival(band_spec(s.prepared.split, true, 1));
  std::size_t steiner_points = 0;  // a band's Steiner points are numbered anew: some must be there
  for (const auto& result : s.results) {
    welder.add(PieceTetMesh(result));
    steiner_points += result.mesh.steiner_points.size();
  }
  EXPECT_GT(steiner_points, 0u);
  expect_pieces_come_back(welder, s.results);
}

// A region that keeps failing cannot grow past the band's edge: after its growths fail, the seams
// heal on over the whole mesh (where it grows as far as it needs) and the result is clean.
TEST(SeamBand, ARegionFailingInTheBandHealsOverTheWholeMesh) {
  const SurfaceMesh input = generate_surface("torus", 1500);
  const MeshedPieces s = mesh_pieces_in_batch(input, 4);
  const std::size_t welded = weld(s.prepared.split, s.prepared.pieces, std::vector<PieceTetMesh>(s.results)).tets.size();
  PreparedPieces prepared = s.prepared;
  Welder welder(prepared.split, prepared.pieces);
  for (const auto& result : s.results) welder.add(PieceTetMesh(result));
  split_bands(welder, prepared, s.options);
  int batches = 0;
  BatchScheduler failing([&](const std::vector<PieceSurface>& regions, const TetgenOptions& tetgen) {
    std::vector<PieceOutcome> outcomes = mesh_pieces_here(regions, PieceRunner(tetgen, s.options.run));
    if (++batches <= 4) outcomes.front().failure = Failure(FailureKind::changed_boundary, -1, {}, "refused by the test");
    return outcomes;
  });
  const MeshResult result = finish_mesh(input, prepared, welder, s.options, failing);
  EXPECT_GE(batches, 5);
  EXPECT_EQ(result.seam.cut_vertices_removed, s.prepared.split.cut_vertex_count());
  EXPECT_GT(result.seam.tets_in, 0);
  EXPECT_EQ(static_cast<std::int64_t>(result.mesh.tets.size()),
            static_cast<std::int64_t>(welded) - result.seam.tets_in + result.seam.tets_out);
  EXPECT_EQ(result.mesh.neighbours, compute_neighbours(result.mesh.tets));
  EXPECT_TRUE(check_mesh(input, result.mesh).ok());
}

// Band parts kept where their pieces were split (the MPI driver's owners, issue 22): the pipeline
// welds each chain from the shares their store cuts and never takes a band part back, and the
// mesh is the one healed from the band parts here. When a region keeps failing, the band parts
// come back to be welded (the seams heal on over the whole mesh) and the mesh is still the same.
TEST(SeamBand, BandPartsKeptWhereTheirPiecesWereSplitHealIntoTheSameMesh) {
  int most_shares = 0;
  for (const char* name : {"torus", "genus3", "nested"})
    for (const int k : {3, 12})
      for (const bool caps : {false, true})
        for (const int failing : {0, 4})
          for (const bool every_other_here : {false, true}) {
          if (failing > 0 && (k != 3 || caps)) continue;
          SCOPED_TRACE(std::string(name) + " k=" + std::to_string(k) + (caps ? " caps" : " cuts") +
                       (failing ? " failing" : "") + (every_other_here ? " every other piece here" : ""));
          const SurfaceMesh input = generate_surface(name, 1500);
          const MeshedPieces s = mesh_pieces_in_batch(input, k);
          MeshOptions options = s.options;
          options.heal = caps ? Heal::on : Heal::off;
          auto heal = [&](bool keeps_bands, int& bands_taken, int& shares_given) {
            PreparedPieces prepared = s.prepared;
            KeptWhereMeshed kept(false, true, keeps_bands);
            Welder welder(prepared.split, prepared.pieces);
            add_split_where_meshed(welder, kept, s, seam_band_spec(prepared.split, HealOptions{caps, 0}), caps,
                                   every_other_here);
            split_bands(welder, prepared, options);
            int batches = 0;
            BatchScheduler meshers([&](const std::vector<PieceSurface>& regions, const TetgenOptions& tetgen) {
              std::vector<PieceOutcome> outcomes = mesh_pieces_here(regions, PieceRunner(tetgen, options.run));
              if (++batches <= failing)
                outcomes.front().failure = Failure(FailureKind::changed_boundary, -1, {}, "refused by the test");
              return outcomes;
            });
            MeshResult result = finish_mesh(input, prepared, welder, options, meshers);
            bands_taken = kept.bands_taken(), shares_given = kept.shares_given();
            return result;
          };
          int taken_here = 0, given_here = 0, taken = 0, given = 0;
          const MeshResult here = heal(false, taken_here, given_here);
          const MeshResult kept = heal(true, taken, given);
          EXPECT_EQ(given_here, 0);
          EXPECT_GT(given, 0);
          // (failing: every band part kept there back, to weld the band)
          EXPECT_EQ(taken, failing ? (every_other_here ? k / 2 : k) : 0);
          most_shares = std::max(most_shares, given);
          EXPECT_EQ(kept.mesh.points, here.mesh.points);
          EXPECT_EQ(kept.mesh.tets, here.mesh.tets);
          EXPECT_EQ(kept.mesh.neighbours, here.mesh.neighbours);
          EXPECT_EQ(kept.mesh.piece, here.mesh.piece);
          EXPECT_EQ(kept.seam.tets_in, here.seam.tets_in);
          EXPECT_TRUE(check_mesh(input, kept.mesh).ok());
        }
  EXPECT_GE(most_shares, 3);
}

}  // namespace
}  // namespace partet
