// Serialization of the MPI messages: pieces and piece results survive a round trip bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "job/pipeline.hpp"
#include "runner/serialize.hpp"
#include "stage_batches.hpp"
#include "stages/generate.hpp"
#include "stages/seam_chain_band.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

// Bitwise equality of point arrays (distinguishes -0.0 from 0.0, compares NaNs).
bool same_bits(const std::vector<Point3>& a, const std::vector<Point3>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(Point3)) == 0);
}

void expect_same(const PieceSurface& a, const PieceSurface& b) {
  EXPECT_EQ(a.index, b.index);
  EXPECT_EQ(a.global_ids, b.global_ids);
  EXPECT_TRUE(same_bits(a.points, b.points));
  EXPECT_EQ(a.triangles, b.triangles);
}

void expect_same(const PieceTetMesh& a, const PieceTetMesh& b) {
  EXPECT_EQ(a.index, b.index);
  EXPECT_EQ(a.surface_point_count, b.surface_point_count);
  EXPECT_TRUE(same_bits(a.mesh.steiner_points, b.mesh.steiner_points));
  EXPECT_EQ(a.mesh.tets, b.mesh.tets);
  EXPECT_EQ(a.mesh.neighbours, b.mesh.neighbours);
}

struct Real {
  PreparedPieces prepared;
  std::vector<PieceTetMesh> results;
};

// Round trips through the forms that cross processes: a piece as a task, a result or a failure
// as an outcome (there is no other).
std::string piece_bytes_of(const PieceSurface& piece) { return serialize_task(piece, TetgenOptions{}); }
PieceSurface piece_from(std::string_view bytes) {
  TetgenOptions ignored;
  return deserialize_task(bytes, ignored);
}
std::string result_bytes_of(const PieceTetMesh& result) {
  PieceOutcome outcome;
  outcome.result = result;
  return serialize_outcome(outcome);
}
PieceTetMesh result_from(std::string_view bytes) { return deserialize_outcome(bytes).result; }

Real real_pieces() {
  MeshOptions options;
  options.pieces = 3;
  options.run.isolate = false;
  options.tetgen.quality = "1.5";  // so that the results have Steiner points
  Real r;
  r.prepared = prepare_pieces(generate_surface("torus", 1000), options);
  for (const auto& piece : r.prepared.pieces) r.results.push_back(tetrahedralize_piece(piece, options.tetgen));
  return r;
}

TEST(Serialize, RealPiecesAndResultsRoundTrip) {
  const Real r = real_pieces();
  // Steiner points travel too.
  ASSERT_TRUE(std::any_of(r.results.begin(), r.results.end(),
                          [](const PieceTetMesh& m) { return !m.mesh.steiner_points.empty(); }));
  for (std::size_t p = 0; p < r.prepared.pieces.size(); ++p) {
    SCOPED_TRACE("piece " + std::to_string(p));
    const PieceSurface& piece = r.prepared.pieces[p];
    const std::string bytes = piece_bytes_of(piece);
    expect_same(piece_from(bytes), piece);
    EXPECT_EQ(piece_bytes_of(piece_from(bytes)), bytes);  // stable encoding

    const PieceTetMesh& result = r.results[p];
    const std::string rbytes = result_bytes_of(result);
    expect_same(result_from(rbytes), result);
    EXPECT_EQ(result_bytes_of(result_from(rbytes)), rbytes);
  }
}

TEST(Serialize, TaskCarriesEveryTetgenOption) {
  const Real r = real_pieces();
  PieceSurface region = r.prepared.pieces[0];
  region.seam_region = true;
  TetgenOptions sent;
  sent.quality = "1.414/10";
  sent.tolerance = "1e-16";
  sent.optimization = "9/7";
  sent.boundary_points = true;
  TetgenOptions received;
  const PieceSurface back = deserialize_task(serialize_task(region, sent), received);
  expect_same(back, region);
  EXPECT_TRUE(back.seam_region);
  EXPECT_EQ(received.quality, sent.quality);
  EXPECT_EQ(received.tolerance, sent.tolerance);
  EXPECT_EQ(received.optimization, sent.optimization);
  EXPECT_TRUE(received.boundary_points);
}

// A chain of the seams goes to a worker as its pieces' shares and its split, and comes back
// healed: the chain that arrives welds and heals as the one sent (the same tets and points), and
// the healed chain (with its ids in the band) and a failure come back whole. Its links come when
// asked (for a mesh left spread), and only then. A malformed split or healed chain is refused.
TEST(Serialize, ChainsOfTheSeamsRoundTrip) {
  const SurfaceMesh input = generate_surface("torus", 1500);
  const MeshedPieces s = mesh_pieces_in_batch(input, 3, 1.0, "1.414");
  const HealOptions options{true, 2, false, true};
  Welder welder(s.prepared.split, s.prepared.pieces);
  for (const auto& result : s.results) welder.add(PieceTetMesh(result));
  const std::vector<ChainShares> chains = gathered_chains(welder, input, s.prepared.split, options);
  ASSERT_FALSE(chains.empty());
  ChainTask sent{static_cast<std::int32_t>(chains.size() - 1), chains.back(), options, TetgenOptions()};
  sent.tetgen.quality = "1.414";
  sent.tetgen.boundary_points = false;
  sent.heal.chain_band_tets = true;
  sent.share_ranks = {1, 3};
  sent.shares_of = 5;
  ChainTask received = deserialize_chain_task(serialize_chain_task(sent));
  EXPECT_EQ(received.index, sent.index);
  EXPECT_EQ(received.share_ranks, sent.share_ranks);
  EXPECT_EQ(received.shares_of, 5);
  EXPECT_TRUE(received.failure.empty());
  EXPECT_TRUE(received.heal.chain_band_tets);
  EXPECT_EQ(received.chain.split.planes, sent.chain.split.planes);
  EXPECT_EQ(received.heal.remove_cap_points, true);
  EXPECT_EQ(received.heal.layers, 2);
  EXPECT_TRUE(received.heal.chain_links);
  EXPECT_EQ(received.tetgen.quality, "1.414");
  EXPECT_FALSE(received.tetgen.boundary_points);
  EXPECT_EQ(received.chain.split.point_ids, sent.chain.split.point_ids);
  EXPECT_TRUE(same_bits(received.chain.split.points, sent.chain.split.points));
  EXPECT_FALSE(sent.chain.split.points.empty());
  EXPECT_EQ(received.chain.split.cut_vertices, sent.chain.split.cut_vertices);
  EXPECT_EQ(received.chain.split.cap_point_plane, sent.chain.split.cap_point_plane);
  EXPECT_EQ(received.chain.split.parent, sent.chain.split.parent);
  EXPECT_EQ(received.chain.split.input_triangles, sent.chain.split.input_triangles);
  EXPECT_EQ(band_tets_of(received.chain), band_tets_of(sent.chain));
  ASSERT_EQ(received.chain.shares.size(), sent.chain.shares.size());
  EXPECT_GE(sent.chain.shares.size(), 2u);
  const HealedChain here = heal_chain(weld_chain(std::move(sent.chain)), options, regions_here(s.options));
  const HealedChain there = heal_chain(weld_chain(std::move(received.chain)), received.heal, regions_here(s.options));
  ASSERT_FALSE(here.failure);
  EXPECT_GT(here.new_points.size(), 0u);
  EXPECT_EQ(there.global_ids, here.global_ids);
  EXPECT_EQ(there.new_points, here.new_points);
  EXPECT_EQ(there.tets, here.tets);
  EXPECT_EQ(there.band_tets, band_tets_of(chains.back()));  // (asked for: chain_band_tets)
  // Its tets come in order_band_tets' order, with their neighbours: rank 0 does not sort them.
  TetMesh ordered;
  ordered.tets = here.tets, ordered.neighbours = here.neighbours, ordered.piece = here.piece;
  order_band_tets(ordered);
  EXPECT_EQ(ordered.tets, here.tets);
  EXPECT_EQ(here.neighbours, compute_neighbours(here.tets));
  std::int32_t index = -1;
  const HealedChain back = deserialize_chain_outcome(serialize_chain_outcome(7, there), index);
  EXPECT_EQ(index, 7);
  EXPECT_EQ(back.global_ids, here.global_ids);
  EXPECT_FALSE(back.global_ids.empty());
  EXPECT_EQ(back.new_points, here.new_points);
  EXPECT_EQ(back.tets, here.tets);
  EXPECT_EQ(back.neighbours, here.neighbours);
  EXPECT_EQ(back.neighbours.size(), here.tets.size());
  EXPECT_EQ(back.band_tets, there.band_tets);
  // With its links (every open face, in its ids) and its tets' components, as block_links finds them.
  std::vector<std::int32_t> label;
  const BlockLinks links = block_links(here.tets, PointIds(), here.neighbours, true, 0, {}, label);
  EXPECT_EQ(back.label, label);
  EXPECT_EQ(back.links.first_tet, links.first_tet);
  EXPECT_EQ(back.links.keys, links.keys);
  EXPECT_EQ(back.links.component, links.component);
  EXPECT_EQ(back.links.face, links.face);
  EXPECT_FALSE(links.keys.empty());
  EXPECT_EQ(back.piece, here.piece);
  // Kept where it healed (keep_healed): rank 0 is sent its points, links and the points its tets
  // use, not its tets.
  HealOptions keeping = options;
  keeping.keep_healed = true;
  EXPECT_TRUE(deserialize_chain_task(serialize_chain_task(ChainTask{sent.index, ChainShares(), keeping, sent.tetgen}))
                  .heal.keep_healed);
  const HealedChain kept = deserialize_chain_outcome(serialize_chain_outcome(7, kept_elsewhere(there, 2, 7)), index);
  EXPECT_EQ(kept.kept_on, 2);
  EXPECT_EQ(kept.kept_as, 7);
  EXPECT_EQ(kept.kept_tets, static_cast<std::int32_t>(here.tets.size()));
  EXPECT_TRUE(kept.tets.empty() && kept.neighbours.empty() && kept.label.empty() && kept.piece.empty());
  EXPECT_EQ(kept.global_ids, here.global_ids);
  EXPECT_EQ(kept.new_points, here.new_points);
  EXPECT_EQ(kept.links.keys, links.keys);
  std::vector<char> used(here.global_ids.size() + here.new_points.size(), 0);
  for (const Tet& t : here.tets)
    for (const std::int32_t v : t) used[static_cast<std::size_t>(v)] = 1;
  EXPECT_EQ(kept.used, used);
  EXPECT_NE(std::count(used.begin(), used.end(), 1), 0);
  // Not asked for its links (an assembled mesh): the same chain, without them.
  HealOptions unlinked = options;
  unlinked.chain_links = false;
  unlinked.chain_band_tets = false;
  ChainTask plain{sent.index, ChainShares(), unlinked, sent.tetgen};
  plain.failure = "rank 2 could not cut its shares";
  const ChainTask plain_back = deserialize_chain_task(serialize_chain_task(plain));
  EXPECT_FALSE(plain_back.heal.chain_links);
  EXPECT_FALSE(plain_back.heal.chain_band_tets);
  EXPECT_FALSE(plain_back.heal.keep_healed);
  EXPECT_EQ(plain_back.failure, plain.failure);
  const HealedChain healed_bare = heal_chain(weld_chain(ChainShares(chains.back())), unlinked, regions_here(s.options));
  const HealedChain bare = deserialize_chain_outcome(serialize_chain_outcome(7, healed_bare), index);
  EXPECT_EQ(bare.tets, here.tets);
  EXPECT_EQ(bare.neighbours, here.neighbours);
  EXPECT_TRUE(bare.label.empty());
  EXPECT_TRUE(bare.links.keys.empty());
  EXPECT_TRUE(bare.band_tets.empty());
  EXPECT_EQ(back.stats.regions, here.stats.regions);
  EXPECT_EQ(back.stats.tets_out, here.stats.tets_out);
  HealedChain astray = there;  // (a tet names a point the chain does not have)
  astray.tets.front()[0] = static_cast<std::int32_t>(astray.global_ids.size() + astray.new_points.size());
  EXPECT_THROW(deserialize_chain_outcome(serialize_chain_outcome(7, astray), index), InternalError);
  ChainTask bad_split{0, chains.back(), options, TetgenOptions()};
  bad_split.chain.split.parent.back() = static_cast<std::int32_t>(bad_split.chain.split.input_triangles.size());
  EXPECT_THROW(deserialize_chain_task(serialize_chain_task(bad_split)), InternalError);
  ChainTask no_coordinates{0, chains.back(), options, TetgenOptions()};
  no_coordinates.chain.split.points.pop_back();
  EXPECT_THROW(deserialize_chain_task(serialize_chain_task(no_coordinates)), InternalError);
  HealedChain failed;
  failed.failure = Failure(FailureKind::other, -1, {1, 2}, "re-meshing the seam near cut plane(s) 1, 2: no");
  const HealedChain failure = deserialize_chain_outcome(serialize_chain_outcome(3, failed), index);
  EXPECT_EQ(index, 3);
  ASSERT_TRUE(failure.failure);
  EXPECT_EQ(failure.failure->planes, (std::vector<int>{1, 2}));
  EXPECT_EQ(failure.failure->message, failed.failure->message);
}

TEST(Serialize, TaskCarriesTheSplitOrder) {
  const Real r = real_pieces();
  TetgenOptions tetgen;
  const SplitOrder sent{BandSpec{10, 1 << 30, 10, 25, 1}, 7};
  std::optional<SplitOrder> received;
  deserialize_task(serialize_task(r.prepared.pieces[0], tetgen, &sent), tetgen, &received);
  ASSERT_TRUE(received);
  EXPECT_EQ(received->attempt, 7);
  EXPECT_EQ(received->spec.input_vertex_count, 10);
  EXPECT_EQ(received->spec.split_point_count, 1 << 30);
  EXPECT_EQ(received->spec.first_removed, 10);
  EXPECT_EQ(received->spec.end_removed, 25);
  EXPECT_EQ(received->spec.layers, 1);
  std::optional<SplitOrder> none;
  deserialize_task(serialize_task(r.prepared.pieces[0], tetgen), tetgen, &none);
  EXPECT_FALSE(none);
}

// A band part's links, made where it was split, travel with it.
void expect_same_links(const std::optional<BandPartLinks>& back, const std::optional<BandPartLinks>& sent) {
  ASSERT_TRUE(sent);
  ASSERT_TRUE(back);
  EXPECT_EQ(back->removed, sent->removed);
  EXPECT_TRUE(back->cap_faces == sent->cap_faces);
  EXPECT_EQ(back->tets, sent->tets);
  EXPECT_GT(sent->cap_faces.size(), 0u);
  EXPECT_EQ(sent->tets.size(), sent->removed.size());
}

// A piece split where it was meshed: its band travels (the bulk stays), with its links, and a
// bulk travels back.
TEST(Serialize, BandsAndBulksRoundTrip) {
  const Real r = real_pieces();
  const SplitSurface& split = r.prepared.split;
  const BandSpec spec{split.input_vertex_count, 1 << 30, split.input_vertex_count,
                      split.input_vertex_count + static_cast<std::int32_t>(split.cut_vertex_count()), 1};
  for (std::size_t p = 0; p < r.results.size(); ++p) {
    SCOPED_TRACE("piece " + std::to_string(p));
    PieceOutcome outcome;
    outcome.seconds = 1.5, outcome.memory_mb = 2.5;
    outcome.band = split_where_meshed(PieceTetMesh(r.results[p]), r.prepared.pieces[p].global_ids, spec);
    const PieceBand& sent = *outcome.band;
    ASSERT_GT(sent.band.tets.size(), 0u);
    ASSERT_GT(sent.bulk.tets.size(), 0u);
    const PieceOutcome back = deserialize_outcome(serialize_outcome(outcome));
    ASSERT_TRUE(back.band);
    EXPECT_FALSE(back.failure);
    EXPECT_EQ(back.seconds, 1.5);
    EXPECT_EQ(back.memory_mb, 2.5);
    const PieceBand& band = *back.band;
    EXPECT_EQ(band.index, sent.index);
    EXPECT_EQ(band.first_steiner, 1 << 30);
    EXPECT_TRUE(same_bits(band.band.steiner_points, sent.band.steiner_points));
    EXPECT_EQ(band.band.tets, sent.band.tets);
    EXPECT_EQ(band.band.neighbours, sent.band.neighbours);
    EXPECT_EQ(band.band_steiner, sent.band_steiner);
    EXPECT_EQ(band.band_tets, sent.band_tets);
    ASSERT_EQ(band.crossings.size(), sent.crossings.size());
    for (std::size_t i = 0; i < band.crossings.size(); ++i) {
      EXPECT_TRUE(band.crossings[i].key == sent.crossings[i].key);
      EXPECT_EQ(band.crossings[i].depth, sent.crossings[i].depth);
    }
    ASSERT_EQ(band.cap_faces_outside.size(), sent.cap_faces_outside.size());
    for (std::size_t i = 0; i < band.cap_faces_outside.size(); ++i)
      EXPECT_TRUE(band.cap_faces_outside[i] == sent.cap_faces_outside[i]);
    expect_same_links(band.links, sent.links);
    PieceOutcome no_links = outcome;
    no_links.band->links.reset();
    EXPECT_FALSE(deserialize_outcome(serialize_outcome(no_links)).band->links);
    EXPECT_FALSE(band.band_kept);
    // Its band part kept there: the tets stay, what the welder needs of them travels.
    PieceOutcome kept_there = outcome;
    KeptBandParts parts;
    parts.keep(*kept_there.band);
    const PieceBand kept = *deserialize_outcome(serialize_outcome(kept_there)).band;
    EXPECT_TRUE(kept.band_kept);
    EXPECT_EQ(kept.band_tet_count, static_cast<std::int64_t>(sent.band.tets.size()));
    EXPECT_EQ(kept.band_split_points, kept_there.band->band_split_points);
    EXPECT_GT(kept.band_split_points.size(), 0u);
    EXPECT_TRUE(kept.band.tets.empty());
    EXPECT_TRUE(kept.band_tets.empty());
    EXPECT_TRUE(same_bits(kept.band.steiner_points, sent.band.steiner_points));
    EXPECT_EQ(kept.band_steiner, sent.band_steiner);
    const PieceBand given_back = parts.take(kept.index);
    EXPECT_EQ(given_back.band.tets, sent.band.tets);
    EXPECT_EQ(given_back.band.neighbours, sent.band.neighbours);
    EXPECT_EQ(given_back.band_tets, sent.band_tets);
    EXPECT_EQ(band.bulk_tets, static_cast<std::int64_t>(sent.bulk.tets.size()));
    EXPECT_EQ(band.bulk_steiner_points, static_cast<std::int64_t>(sent.bulk.steiner_points.size()));
    EXPECT_TRUE(band.bulk.tets.empty());  // the bulk stays where it was split
    const TetBlock bulk = deserialize_block(serialize_block(sent.bulk));
    EXPECT_TRUE(same_bits(bulk.steiner_points, sent.bulk.steiner_points));
    EXPECT_EQ(bulk.tets, sent.bulk.tets);
    EXPECT_EQ(bulk.neighbours, sent.bulk.neighbours);
    EXPECT_EQ(bulk.rim, sent.bulk.rim);
    EXPECT_FALSE(bulk.numbered);
    TetBlock numbered = sent.bulk;
    numbered.numbered = true;
    EXPECT_TRUE(deserialize_block(serialize_block(numbered)).numbered);
  }
}

// A band grows where its bulk is kept: the band goes there with its neighbours' crossings, and
// the band grown there comes back, without the bulk; both as grow_band made them here.
TEST(Serialize, ABandToGrowAndTheBandGrownRoundTrip) {
  const Real r = real_pieces();
  const SplitSurface& split = r.prepared.split;
  const BandSpec spec{split.input_vertex_count, 1 << 30, split.input_vertex_count,
                      split.input_vertex_count + static_cast<std::int32_t>(split.cut_vertex_count()), 1};
  std::vector<PieceBand> pieces;
  for (std::size_t p = 0; p < r.results.size(); ++p)
    pieces.push_back(split_where_meshed(PieceTetMesh(r.results[p]), r.prepared.pieces[p].global_ids, spec));
  ASSERT_GE(pieces.size(), 3u);
  const PieceBand& middle = pieces[1];
  BandToGrow sent{1, spec, middle.band, middle.band_steiner, middle.band_tets, pieces[0].crossings};
  sent.crossings.insert(sent.crossings.end(), pieces[2].crossings.begin(), pieces[2].crossings.end());
  ASSERT_GT(sent.crossings.size(), 0u);
  BandToGrow kept_there = sent;
  kept_there.band_kept = true;
  EXPECT_TRUE(deserialize_band_to_grow(serialize_band_to_grow(kept_there)).band_kept);
  BandToGrow back = deserialize_band_to_grow(serialize_band_to_grow(sent));
  EXPECT_FALSE(back.band_kept);
  EXPECT_EQ(back.index, 1);
  EXPECT_EQ(back.spec.split_point_count, 1 << 30);
  EXPECT_EQ(back.spec.end_removed, spec.end_removed);
  EXPECT_EQ(back.spec.layers, 1);
  EXPECT_TRUE(same_bits(back.band.steiner_points, sent.band.steiner_points));
  EXPECT_EQ(back.band.tets, sent.band.tets);
  EXPECT_EQ(back.band.neighbours, sent.band.neighbours);
  EXPECT_EQ(back.band_steiner, sent.band_steiner);
  EXPECT_EQ(back.band_tets, sent.band_tets);
  ASSERT_EQ(back.crossings.size(), sent.crossings.size());
  for (std::size_t i = 0; i < back.crossings.size(); ++i) {
    EXPECT_TRUE(back.crossings[i].key == sent.crossings[i].key);
    EXPECT_EQ(back.crossings[i].depth, sent.crossings[i].depth);
  }
  const PieceBand here = grow_band(std::move(sent), TetBlock(middle.bulk));
  PieceBand there = grow_band(std::move(back), TetBlock(middle.bulk));
  EXPECT_EQ(here.band.tets.size() + here.bulk.tets.size(), middle.band.tets.size() + middle.bulk.tets.size());
  there.bulk = TetBlock();
  const PieceBand grown = deserialize_grown_band(serialize_grown_band(there));
  EXPECT_EQ(grown.index, 1);
  EXPECT_TRUE(same_bits(grown.band.steiner_points, here.band.steiner_points));
  EXPECT_EQ(grown.band.tets, here.band.tets);
  EXPECT_EQ(grown.band.neighbours, here.band.neighbours);
  EXPECT_EQ(grown.band_steiner, here.band_steiner);
  EXPECT_EQ(grown.band_tets, here.band_tets);
  EXPECT_EQ(grown.bulk_tets, static_cast<std::int64_t>(here.bulk.tets.size()));
  EXPECT_EQ(grown.bulk_steiner_points, static_cast<std::int64_t>(here.bulk.steiner_points.size()));
  expect_same_links(grown.links, here.links);
  EXPECT_FALSE(grown.bulk.in);  // the bulk stays where the band grew
  EXPECT_THROW(serialize_grown_band(here), InternalError);
}

// The plan of the band parts a rank keeps goes to it, with the rank that heals each chain, and
// their shares of a chain go there; a plan naming a chain without a healing rank is refused.
TEST(Serialize, TheSharePlanAndAChainsSharesRoundTrip) {
  std::vector<BandPartPlan> plans(2);
  plans[0] = {BandPartPlace{3, 100, 1 << 30, 5000}, {2, -1, 0}};
  plans[1] = {BandPartPlace{65535, 0, 7, 7}, {}};
  const std::vector<int> order{2, 0, 1}, healers{3, 0, 1};
  std::vector<BandPartPlan> plans_back;
  std::vector<int> order_back, healers_back;
  deserialize_share_plan(serialize_share_plan(plans, order, healers), plans_back, order_back, healers_back);
  EXPECT_EQ(order_back, order);
  EXPECT_EQ(healers_back, healers);
  EXPECT_THROW(deserialize_share_plan(serialize_share_plan(plans, order, {3, 0}), plans_back, order_back, healers_back),
               InternalError);
  ASSERT_EQ(plans_back.size(), plans.size());
  for (std::size_t i = 0; i < plans.size(); ++i) {
    EXPECT_EQ(plans_back[i].place.piece, plans[i].place.piece);
    EXPECT_EQ(plans_back[i].place.first_tet, plans[i].place.first_tet);
    EXPECT_EQ(plans_back[i].place.steiner_from, plans[i].place.steiner_from);
    EXPECT_EQ(plans_back[i].place.steiner_to, plans[i].place.steiner_to);
    EXPECT_EQ(plans_back[i].chain_of_part, plans[i].chain_of_part);
  }
  std::vector<ChainShare> shares(2);
  shares[0].chain = 4, shares[0].piece = 9;
  shares[0].band_tets = {10, 11};
  shares[0].tets = {{{1, 2, 3, 5000}}, {{1, 2, 5000, 5001}}};
  shares[0].neighbours = {{{-1, -1, 1, -1}}, {{-1, 0, -1, -1}}};
  shares[0].point_ids = {1, 2, 3, 5000, 5001};
  shares[0].points = {{0.1, -2.5e300, 3}, {4, 5, 6}};  // (its Steiner points': 5000 and 5001)
  shares[1].chain = 4, shares[1].piece = 10;
  const std::vector<ChainShare> back = deserialize_chain_shares(serialize_chain_shares(shares));
  ASSERT_EQ(back.size(), shares.size());
  for (std::size_t i = 0; i < shares.size(); ++i) {
    EXPECT_EQ(back[i].chain, shares[i].chain);
    EXPECT_EQ(back[i].piece, shares[i].piece);
    EXPECT_EQ(back[i].band_tets, shares[i].band_tets);
    EXPECT_EQ(back[i].tets, shares[i].tets);
    EXPECT_EQ(back[i].neighbours, shares[i].neighbours);
    EXPECT_EQ(back[i].point_ids, shares[i].point_ids);
    EXPECT_TRUE(same_bits(back[i].points, shares[i].points));
  }
  EXPECT_TRUE(deserialize_chain_shares(serialize_chain_shares({})).empty());
  shares[0].neighbours.pop_back();
  EXPECT_THROW(deserialize_chain_shares(serialize_chain_shares(shares)), InternalError);
  shares[0].neighbours.push_back({{-1, 0, -1, -1}});
  shares[0].points.resize(6);  // (more coordinates than points)
  EXPECT_THROW(deserialize_chain_shares(serialize_chain_shares(shares)), InternalError);
}

// The numbering's shares of the kept bulks, as they go to the ranks that keep them.
TEST(Serialize, BulkSharesRoundTrip) {
  std::vector<BulkShare> sent(3);
  sent[0] = {4, 1 << 30, BulkNumbering{}};
  sent[0].numbering.split_points = 1000, sent[0].numbering.first_steiner = 1990;
  const auto dropped_split = std::make_shared<const std::vector<std::int32_t>>(std::vector<std::int32_t>{3, 700, 999});
  sent[0].numbering.dropped_split = dropped_split;
  sent[0].numbering.dropped_steiner = {0, 5};
  sent[1] = {0, 1000, BulkNumbering{}};
  sent[1].numbering.split_points = 1000, sent[1].numbering.first_steiner = 997;
  sent[1].numbering.dropped_split = std::make_shared<const std::vector<std::int32_t>>(*dropped_split);  // a copy
  sent[2].piece = 65535;
  sent[2].numbering.dropped_split = dropped_split;
  const std::vector<BulkShare> back = deserialize_bulk_shares(serialize_bulk_shares(sent));
  ASSERT_EQ(back.size(), sent.size());
  for (std::size_t i = 0; i < sent.size(); ++i) {
    EXPECT_EQ(back[i].piece, sent[i].piece);
    EXPECT_EQ(back[i].first_steiner, sent[i].first_steiner);
    EXPECT_EQ(back[i].numbering.split_points, sent[i].numbering.split_points);
    EXPECT_EQ(back[i].numbering.first_steiner, sent[i].numbering.first_steiner);
    EXPECT_EQ(*back[i].numbering.dropped_split, *dropped_split);
    EXPECT_EQ(back[i].numbering.dropped_steiner, sent[i].numbering.dropped_steiner);
  }
  // The list travels once and is held once.
  EXPECT_EQ(back[0].numbering.dropped_split, back[2].numbering.dropped_split);
  EXPECT_TRUE(deserialize_bulk_shares(serialize_bulk_shares({})).empty());
  sent[1].numbering.dropped_split = std::make_shared<const std::vector<std::int32_t>>();
  EXPECT_THROW(serialize_bulk_shares(sent), InternalError);
}

// A spread mesh's messages: the links of the bulks a rank keeps, and where every bulk's rows are.
TEST(Serialize, BulkLinksAndPlacementRoundTrip) {
  BlockLinks links;
  links.first_tet = {0, 17};
  links.keys = {{1, 2, 3}, {4, 5, 2147483647}};
  links.component = {0, 1};
  links.face = {4 * 17 + 3, (std::uint64_t{1} << 34) + 1};
  const std::vector<std::pair<int, BlockLinks>> sent{{3, links}, {65535, BlockLinks{}}};
  const auto back = deserialize_bulk_links(serialize_bulk_links(sent));
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].first, 3);
  EXPECT_EQ(back[0].second.first_tet, links.first_tet);
  EXPECT_EQ(back[0].second.keys, links.keys);
  EXPECT_EQ(back[0].second.component, links.component);
  EXPECT_EQ(back[0].second.face, links.face);
  EXPECT_EQ(back[1].first, 65535);
  EXPECT_TRUE(back[1].second.keys.empty());
  EXPECT_TRUE(deserialize_bulk_links(serialize_bulk_links({})).empty());
  BlockLinks unmatched = links;
  unmatched.component.pop_back();  // a key without its component
  EXPECT_THROW(deserialize_bulk_links(serialize_bulk_links({{0, unmatched}})), InternalError);
  BlockLinks faceless = links;
  faceless.face.pop_back();  // a key without its face
  EXPECT_THROW(deserialize_bulk_links(serialize_bulk_links({{0, faceless}})), InternalError);

  std::vector<SpreadBulk> bulks(2);
  bulks[0].piece = 7, bulks[0].first_point = std::int64_t{1} << 33, bulks[0].points = 5;
  bulks[0].first_tet = 9, bulks[0].tets = 11, bulks[0].solid = {1, 2};
  bulks[0].here = true, bulks[0].block.tets = {{0, 1, 2, 3}};  // neither travels
  std::vector<BandRun> runs(3);
  runs[0].chain = 4, runs[0].rank = 0, runs[0].first_row = 20, runs[0].tets = 3;  // here: does not travel
  runs[1].chain = 5, runs[1].rank = 3, runs[1].first_row = std::int64_t{1} << 32, runs[1].tets = 2;
  runs[1].solid = {1, 4}, runs[1].point_ids = {7, -1, std::int64_t{1} << 33};
  runs[2].chain = 6, runs[2].rank = 1;
  const std::vector<BandRun> runs_back = deserialize_band_runs(serialize_band_runs(runs, true));
  ASSERT_EQ(runs_back.size(), 2u);
  EXPECT_EQ(runs_back[0].chain, 5);
  EXPECT_EQ(runs_back[0].rank, 3);
  EXPECT_EQ(runs_back[0].first_row, std::int64_t{1} << 32);
  EXPECT_EQ(runs_back[0].tets, 2);
  EXPECT_EQ(runs_back[0].solid, runs[1].solid);
  EXPECT_EQ(runs_back[0].point_ids, runs[1].point_ids);
  EXPECT_EQ(runs_back[1].chain, 6);
  EXPECT_EQ(deserialize_band_runs(serialize_band_runs(runs, false)).size(), 3u);
  const std::vector<SpreadBulk> placed = deserialize_placement(serialize_placement(bulks));
  ASSERT_EQ(placed.size(), 2u);
  EXPECT_EQ(placed[0].piece, 7);
  EXPECT_EQ(placed[0].first_point, std::int64_t{1} << 33);
  EXPECT_EQ(placed[0].points, 5);
  EXPECT_EQ(placed[0].first_tet, 9);
  EXPECT_EQ(placed[0].tets, 11);
  EXPECT_EQ(placed[0].solid, bulks[0].solid);
  EXPECT_FALSE(placed[0].here);
  EXPECT_TRUE(placed[0].block.tets.empty());
  EXPECT_TRUE(placed[1].solid.empty());
  const std::string bytes = serialize_placement(bulks);
  EXPECT_ANY_THROW(deserialize_placement(bytes.substr(0, bytes.size() - 3)));
}

TEST(Serialize, SpecialValuesAndNegativeIds) {
  PieceSurface piece;
  piece.index = 2147483647;
  const double inf = std::numeric_limits<double>::infinity();
  piece.points = {{-0.0, 0.0, std::numeric_limits<double>::denorm_min()},
                  {std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(), inf},
                  {-inf, std::numeric_limits<double>::quiet_NaN(), std::nextafter(1.0, 2.0)},
                  {0.1, 1.0 / 3.0, -1e-308}};
  piece.global_ids = {0, 7, 2147483647, 12};
  piece.triangles = {{0, 1, 2}, {-1, 3, 2147483647}};
  const PieceSurface back = piece_from(piece_bytes_of(piece));
  expect_same(back, piece);
  EXPECT_TRUE(std::signbit(back.points[0][0]));
  EXPECT_TRUE(std::isnan(back.points[2][1]));

  PieceTetMesh result;
  result.index = -5;
  result.surface_point_count = 123456789;
  result.mesh.steiner_points = piece.points;
  result.mesh.tets = {{0, 1, 2, 3}, {-1, -2, 2147483647, -2147483647 - 1}};
  result.mesh.neighbours = {{-1, 1, -1, -1}, {0, -1, -1, -1}};
  expect_same(result_from(result_bytes_of(result)), result);
}

TEST(Serialize, EmptyMessages) {
  const PieceSurface empty_piece;
  expect_same(piece_from(piece_bytes_of(empty_piece)), empty_piece);
  const PieceTetMesh empty_result;
  expect_same(result_from(result_bytes_of(empty_result)), empty_result);
  // An empty vector followed by a full one.
  PieceTetMesh partial;
  partial.index = 1;
  partial.mesh.tets = {{0, 1, 2, 3}};
  partial.mesh.neighbours = {{-1, -1, -1, -1}};
  expect_same(result_from(result_bytes_of(partial)), partial);
}

TEST(Serialize, CompactBinaryEncoding) {
  // Flat blocks: the message is the raw data plus a small header, not a text encoding.
  const Real r = real_pieces();
  const PieceSurface& piece = r.prepared.pieces[0];
  const std::size_t payload = piece.points.size() * sizeof(Point3) + piece.triangles.size() * sizeof(Triangle) +
                              piece.global_ids.size() * sizeof(std::int32_t);
  const std::string bytes = piece_bytes_of(piece);
  EXPECT_GE(bytes.size(), payload);
  EXPECT_LE(bytes.size(), payload + 128);  // headers, and the task's TetGen options
}

TEST(Serialize, TruncatedMessageIsRejected) {
  const Real r = real_pieces();
  const std::string bytes = result_bytes_of(r.results[0]);
  EXPECT_ANY_THROW(result_from(bytes.substr(0, bytes.size() / 2)));
  const std::string pbytes = piece_bytes_of(r.prepared.pieces[0]);
  EXPECT_ANY_THROW(piece_from(pbytes.substr(0, pbytes.size() - 1)));
}

TEST(Serialize, FailuresAndOutcomesRoundTrip) {
  const Failure failure{FailureKind::self_intersection, -1, {0, 3, 7}, "near cut plane(s) 0, 3, 7: boom", {12, 40}};
  PieceOutcome carrying;
  carrying.failure = failure;
  const Failure back = *deserialize_outcome(serialize_outcome(carrying)).failure;
  EXPECT_EQ(back.kind, failure.kind);
  EXPECT_EQ(back.piece, failure.piece);
  EXPECT_EQ(back.planes, failure.planes);
  EXPECT_EQ(back.message, failure.message);
  EXPECT_EQ(back.faces, failure.faces);  // the triangles TetGen named, for the input-or-cut diagnosis

  PieceOutcome failed;
  failed.failure = Failure{FailureKind::crashed, 5, {}, "meshing crashed (signal 6)"};
  const PieceOutcome f = deserialize_outcome(serialize_outcome(failed));
  ASSERT_TRUE(f.failure);
  EXPECT_EQ(f.failure->kind, FailureKind::crashed);
  EXPECT_EQ(f.failure->text(), "piece 5: meshing crashed (signal 6)");

  const Real r = real_pieces();
  PieceOutcome ok;
  ok.result = r.results[1];
  const PieceOutcome o = deserialize_outcome(serialize_outcome(ok));
  EXPECT_FALSE(o.failure);
  expect_same(o.result, r.results[1]);
  // The reply carries the seconds and memory beside the result.
  ok.seconds = 2.5;
  ok.memory_mb = 12.25;
  EXPECT_EQ(deserialize_outcome(serialize_outcome(ok)).seconds, 2.5);
  EXPECT_EQ(deserialize_outcome(serialize_outcome(ok)).memory_mb, 12.25);

  EXPECT_THROW(deserialize_outcome(""), InternalError);
  EXPECT_THROW(deserialize_outcome("X123"), InternalError);
}

TEST(Serialize, CapTasksAndShapesRoundTrip) {
  // A cap's border goes to a worker and its shape comes back: the shape built from the border
  // that crossed is the one built from the border itself, bit for bit.
  const SurfaceMesh s = generate_surface("torus", 3000);
  const auto planes = choose_cut_planes(s, 3);
  SplitSurface split = split_at_planes(s, planes);
  const CapBorder border = CapBuilder(split, planes, 2.0).border(1);
  const std::string task = serialize_cap_task(border);
  ASSERT_EQ(task_kind(task), TaskKind::cap);
  const CapBorder sent = deserialize_cap_task(task);
  EXPECT_EQ(sent.plane, 1);
  EXPECT_EQ(sent.cut.normal, border.cut.normal);
  EXPECT_EQ(sent.cut.offset, border.cut.offset);
  EXPECT_EQ(sent.density, 2.0);
  EXPECT_EQ(sent.global_ids, border.global_ids);
  EXPECT_EQ(sent.points, border.points);
  EXPECT_EQ(sent.chords, border.chords);

  CapOutcome outcome;
  outcome.shape = triangulate_cap(sent);
  outcome.seconds = 0.75;
  const std::string reply = serialize_cap_outcome(outcome);
  ASSERT_TRUE(is_cap_outcome(reply));
  const CapOutcome back = deserialize_cap_outcome(reply);
  const CapShape local = triangulate_cap(border);
  EXPECT_FALSE(back.failure);
  EXPECT_EQ(back.seconds, 0.75);
  EXPECT_EQ(back.shape.plane, 1);
  EXPECT_EQ(back.shape.triangles, local.triangles);
  EXPECT_EQ(back.shape.interior_points, local.interior_points);

  CapOutcome failed;
  failed.failure = Failure{FailureKind::self_intersection, -1, {}, "cut plane 1: the loops cross"};
  const CapOutcome f = deserialize_cap_outcome(serialize_cap_outcome(failed));
  ASSERT_TRUE(f.failure);
  EXPECT_EQ(f.failure->kind, FailureKind::self_intersection);
  EXPECT_EQ(f.failure->message, "cut plane 1: the loops cross");

  // Tasks and replies of the two kinds are told apart, never misread.
  const Real r = real_pieces();
  const std::string piece_task = piece_bytes_of(r.prepared.pieces[0]);
  EXPECT_EQ(task_kind(piece_task), TaskKind::piece);
  EXPECT_THROW(deserialize_cap_task(piece_task), InternalError);
  TetgenOptions ignored;
  EXPECT_THROW(deserialize_task(task, ignored), InternalError);
  EXPECT_THROW(task_kind("Z"), InternalError);
  EXPECT_FALSE(is_cap_outcome(serialize_outcome(PieceOutcome{})));
  EXPECT_THROW(deserialize_outcome(reply), InternalError);
}

}  // namespace
}  // namespace partet
