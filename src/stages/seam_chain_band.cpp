#include "stages/seam_chain_band.hpp"

#include <algorithm>
#include <numeric>
#include <unordered_map>

#include "common/radix_sort.hpp"
#include "common/stage_timer.hpp"
#include "partet/errors.hpp"
#include "stages/seam_chains.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

// The id ranges of the split surface's points in the band: input vertices, cut vertices, caps'
// interior points; Steiner points follow.
struct SplitRanges {
  std::int32_t first_cut, first_cap, end_caps;
  explicit SplitRanges(const SplitSurface& split)
      : first_cut(split.input_vertex_count),
        first_cap(first_cut + split.cut_vertex_count()),
        end_caps(first_cap + static_cast<std::int32_t>(split.cap_point_plane.size())) {}
  explicit SplitRanges(const ChainSplit& split)
      : first_cut(split.first_cut), first_cap(split.first_cap), end_caps(split.end_caps) {}
};

std::vector<int> chain_of_planes(const SplitSurface& split, const std::vector<std::vector<int>>& chains) {
  std::vector<int> chain_of_plane(static_cast<std::size_t>(split.plane_count()), -1);
  for (std::size_t c = 0; c < chains.size(); ++c)
    for (int p : chains[c]) chain_of_plane.at(static_cast<std::size_t>(p)) = static_cast<int>(c);
  return chain_of_plane;
}

// By v - first_cut: the chain of each vertex healing removes (-1: none of them).
std::vector<int> chains_of_removed(const SplitSurface& split, const HealOptions& options,
                                   const std::vector<int>& chain_of_plane) {
  const std::size_t cuts = split.cut_vertex_plane.size();
  const std::size_t caps = options.remove_cap_points ? split.cap_point_plane.size() : 0;
  std::vector<int> chain_of(cuts + caps, -1);
  for (std::size_t i = 0; i < cuts; ++i) chain_of[i] = chain_of_plane[split.cut_vertex_plane[i]];
  for (std::size_t i = 0; i < caps; ++i) chain_of[cuts + i] = chain_of_plane[split.cap_point_plane[i]];
  return chain_of;
}

std::int32_t local_id(const std::vector<std::int32_t>& global_ids, std::int32_t id) {
  const auto it = std::lower_bound(global_ids.begin(), global_ids.end(), id);
  if (it == global_ids.end() || *it != id) throw InternalError("a seam chain's band lacks a point its healing needs");
  return static_cast<std::int32_t>(it - global_ids.begin());
}

Triangle local_triangle(const std::vector<std::int32_t>& global_ids, const Triangle& t) {
  return {local_id(global_ids, t[0]), local_id(global_ids, t[1]), local_id(global_ids, t[2])};
}

// The chain's tets, points and pieces in local ids (its points: the band's ids its tets use).
void cut_out_tets(const TetMesh& band, ChainBand& chain) {
  for (auto t : chain.band_tets)
    for (auto v : band.tets[t]) chain.global_ids.push_back(v);
  std::sort(chain.global_ids.begin(), chain.global_ids.end());
  chain.global_ids.erase(std::unique(chain.global_ids.begin(), chain.global_ids.end()), chain.global_ids.end());
  chain.mesh.points.reserve(chain.global_ids.size());
  for (auto id : chain.global_ids) chain.mesh.points.push_back(band.points[id]);
  chain.mesh.tets.reserve(chain.band_tets.size());
  chain.mesh.neighbours.reserve(chain.band_tets.size());
  for (auto t : chain.band_tets) {
    Tet local, across;
    for (int j = 0; j < 4; ++j) {
      local[j] = local_id(chain.global_ids, band.tets[t][j]);
      const std::int32_t nb = band.neighbours[t][j];
      const auto it = std::lower_bound(chain.band_tets.begin(), chain.band_tets.end(), nb);
      across[j] = nb >= 0 && it != chain.band_tets.end() && *it == nb
                      ? static_cast<std::int32_t>(it - chain.band_tets.begin())
                      : -1;
    }
    chain.mesh.tets.push_back(local);
    chain.mesh.neighbours.push_back(across);
    if (band.piece.size() == band.tets.size()) chain.mesh.piece.push_back(band.piece[t]);
  }
}

// The planes of the chain's points (ids, ascending) in [from, to), from the ids listed (ascending)
// with their planes. Throws InternalError when one is not listed.
std::vector<std::int32_t> planes_of(const std::vector<std::int32_t>& ids, std::int32_t from, std::int32_t to,
                                    const std::vector<std::int32_t>& listed, const std::vector<std::int32_t>& plane) {
  std::vector<std::int32_t> planes;
  std::size_t at = 0;
  for (auto it = std::lower_bound(ids.begin(), ids.end(), from); it != ids.end() && *it < to; ++it) {
    while (at < listed.size() && listed[at] < *it) ++at;
    if (at == listed.size() || listed[at] != *it)
      throw InternalError("a seam chain's split lacks a point its tets use");
    planes.push_back(plane[at]);
  }
  return planes;
}

// What healing reads of the split surface, in the chain's ids (global_ids known): the planes of
// its cut vertices and caps' points, its split triangles and their input triangles.
void cut_out_split(ChainSplit&& split, ChainBand& chain) {
  const std::vector<std::int32_t>& ids = chain.global_ids;
  SplitSurface& local = chain.split;
  chain.planes = std::move(split.planes);
  local.input_vertex_count =
      static_cast<std::int32_t>(std::lower_bound(ids.begin(), ids.end(), split.first_cut) - ids.begin());
  local.cut_vertex_plane = planes_of(ids, split.first_cut, split.first_cap, split.cut_vertices, split.cut_vertex_plane);
  local.cap_point_plane = planes_of(ids, split.first_cap, split.end_caps, split.cap_points, split.cap_point_plane);
  local.triangles.reserve(split.triangles.size());
  for (const Triangle& t : split.triangles) local.triangles.push_back(local_triangle(ids, t));
  local.parent = std::move(split.parent);
  chain.input.triangles.reserve(split.input_triangles.size());
  for (const Triangle& t : split.input_triangles) chain.input.triangles.push_back(local_triangle(ids, t));
}

// Where the coordinates of each of the share's points are: its Steiner points' in the share, the
// split surface's in the chain's split. Throws InternalError when the split lacks one.
void coordinates_of(const ChainShare& share, const ChainSplit& split, std::vector<const Point3*>& where) {
  const std::size_t steiner_from = share.point_ids.size() - share.points.size();
  std::size_t at = 0;
  for (std::size_t i = 0; i < steiner_from; ++i) {
    const std::int32_t id = share.point_ids[i];
    while (at < split.point_ids.size() && split.point_ids[at] < id) ++at;
    if (at == split.point_ids.size() || split.point_ids[at] != id)
      throw InternalError("a seam chain's split lacks a point of the split surface its tets use");
    where.push_back(&split.points[at]);
  }
  if (steiner_from < share.point_ids.size() && share.point_ids[steiner_from] < split.end_caps)
    throw InternalError("a seam chain's share holds coordinates of the split surface's points");
  for (const Point3& point : share.points) where.push_back(&point);
}

// The shares' points, merged by id, into the chain's points (global_ids, mesh.points); per point
// of every share, in share order, its id in the chain (the shares' tets are numbered through it).
std::vector<std::int32_t> weld_points(const std::vector<ChainShare>& shares, const ChainSplit& split,
                                      ChainBand& chain) {
  std::vector<std::pair<std::int32_t, std::uint32_t>> points;  // (band id, place among every share's points)
  std::vector<const Point3*> where;                            // by place
  for (const ChainShare& share : shares) {
    for (const std::int32_t id : share.point_ids) points.emplace_back(id, static_cast<std::uint32_t>(points.size()));
    coordinates_of(share, split, where);
  }
  radix_sort(points, [](const auto& p) { return static_cast<std::uint64_t>(static_cast<std::uint32_t>(p.first)); });
  std::vector<std::int32_t> in_chain(points.size());
  for (const auto& [id, place] : points) {
    if (chain.global_ids.empty() || chain.global_ids.back() != id) {
      chain.global_ids.push_back(id);
      chain.mesh.points.push_back(*where[place]);
    }
    in_chain[place] = static_cast<std::int32_t>(chain.global_ids.size() - 1);
  }
  return in_chain;
}

// The chain's open faces on the planes (their three points are cut vertices or caps' points),
// 4 * tet + j: the only faces two pieces' shares can meet at.
std::vector<std::uint64_t> open_faces_on_planes(const ChainBand& chain, const SplitRanges& ranges) {
  std::vector<char> on_planes(chain.global_ids.size());
  for (std::size_t v = 0; v < on_planes.size(); ++v)
    on_planes[v] = chain.global_ids[v] >= ranges.first_cut && chain.global_ids[v] < ranges.end_caps;
  std::vector<std::uint64_t> faces;
  for (std::size_t t = 0; t < chain.mesh.tets.size(); ++t)
    for (int j = 0; j < 4; ++j) {
      if (chain.mesh.neighbours[t][j] >= 0) continue;
      const Tet& tet = chain.mesh.tets[t];
      const bool on = on_planes[tet[(j + 1) % 4]] && on_planes[tet[(j + 2) % 4]] && on_planes[tet[(j + 3) % 4]];
      if (on) faces.push_back(4 * static_cast<std::uint64_t>(t) + static_cast<std::uint64_t>(j));
    }
  return faces;
}

// The shares' tets, in band order, in the chain's ids (in_chain: weld_points'); joined across the
// caps where two pieces' shares meet, as the welded band joins them.
void weld_tets(const std::vector<ChainShare>& shares, const std::vector<std::int32_t>& in_chain,
               const SplitRanges& ranges, ChainBand& chain) {
  std::size_t first_point = 0;  // the share's first place in in_chain
  for (const ChainShare& share : shares) {
    if (!chain.band_tets.empty() && !share.band_tets.empty() && share.band_tets.front() <= chain.band_tets.back())
      throw InternalError("two shares of a seam chain hold the same tets of the band");
    const auto first = static_cast<std::int32_t>(chain.mesh.tets.size());
    const auto points = static_cast<std::uint32_t>(share.point_ids.size());
    chain.band_tets.insert(chain.band_tets.end(), share.band_tets.begin(), share.band_tets.end());
    for (std::size_t t = 0; t < share.tets.size(); ++t) {
      Tet local, across = share.neighbours[t];
      for (int j = 0; j < 4; ++j) {
        if (static_cast<std::uint32_t>(share.tets[t][j]) >= points)
          throw InternalError("a seam chain's share names a point it does not hold");
        local[j] = in_chain[first_point + static_cast<std::size_t>(share.tets[t][j])];
        if (across[j] >= 0) across[j] += first;
      }
      chain.mesh.tets.push_back(local);
      chain.mesh.neighbours.push_back(across);
    }
    chain.mesh.piece.resize(chain.mesh.tets.size(), share.piece);
    first_point += points;
  }
  connect_faces(chain.mesh.tets, chain.mesh.neighbours, open_faces_on_planes(chain, ranges));
}

// The shares with tets, by their first tet in the band (as weld_tets takes them). Throws
// InternalError when they are of several chains.
void order_shares(std::vector<ChainShare>& shares) {
  for (const ChainShare& share : shares)
    if (share.chain != shares.front().chain)
      throw InternalError("a seam chain was welded from shares of several chains");
  shares.erase(std::remove_if(shares.begin(), shares.end(), [](const ChainShare& s) { return s.band_tets.empty(); }),
               shares.end());
  std::sort(shares.begin(), shares.end(),
            [](const ChainShare& a, const ChainShare& b) { return a.band_tets.front() < b.band_tets.front(); });
}

}  // namespace

std::vector<std::vector<std::int32_t>> chain_split_triangles(const SplitSurface& split,
                                                             const std::vector<std::vector<int>>& chains) {
  const std::vector<int> chain_of_plane = chain_of_planes(split, chains);
  std::vector<std::vector<std::int32_t>> triangles(chains.size());
  for (std::size_t t = 0; t < split.triangles.size(); ++t) {
    const Triangle& f = split.triangles[t];
    const auto cut = std::find_if(f.begin(), f.end(), [&](std::int32_t v) { return split.is_cut_vertex(v); });
    if (cut == f.end()) continue;
    const int chain = chain_of_plane[split.cut_vertex_plane[*cut - split.input_vertex_count]];
    if (chain >= 0) triangles[chain].push_back(static_cast<std::int32_t>(t));
  }
  return triangles;
}

BandPartChains band_part_chains(const TetBlock& band, const std::vector<int>& chain_of_part) {
  const std::vector<std::int32_t> part = band_part_labels(band);
  BandPartChains chains;
  for (const int chain : chain_of_part)
    if (chain >= 0) chains.chains.push_back(chain);
  std::sort(chains.chains.begin(), chains.chains.end());
  chains.chains.erase(std::unique(chains.chains.begin(), chains.chains.end()), chains.chains.end());
  chains.tets.resize(chains.chains.size());
  chains.at.assign(band.tets.size(), -1);
  for (std::size_t t = 0; t < band.tets.size(); ++t) {
    const int chain = chain_of_part.at(static_cast<std::size_t>(part[t]));
    if (chain < 0) continue;
    const auto at = std::lower_bound(chains.chains.begin(), chains.chains.end(), chain) - chains.chains.begin();
    std::vector<std::int32_t>& tets = chains.tets[static_cast<std::size_t>(at)];
    chains.at[t] = static_cast<std::int32_t>(tets.size());
    tets.push_back(static_cast<std::int32_t>(t));
  }
  return chains;
}

ChainShare chain_share(const TetBlock& band, const BandPartChains& in_chains, std::size_t i,
                       const BandPartPlace& place) {
  const std::vector<std::int32_t>& tets = in_chains.tets.at(i);
  ChainShare share;
  share.chain = in_chains.chains.at(i);
  share.piece = place.piece;
  auto band_id = [&](std::int32_t v) {
    return v >= place.steiner_from ? v - place.steiner_from + place.steiner_to : v;
  };
  share.band_tets.reserve(tets.size());
  share.tets.reserve(tets.size());
  share.neighbours.reserve(tets.size());
  for (const std::int32_t t : tets) {
    share.band_tets.push_back(place.first_tet + t);
    Tet tet, across;
    for (int j = 0; j < 4; ++j) {
      tet[j] = band_id(band.tets[t][j]);
      const std::int32_t nb = band.neighbours[t][j];
      across[j] = nb >= 0 ? in_chains.at[nb] : -1;  // (a neighbour is in the tet's part, so in its share)
    }
    share.tets.push_back(tet);
    share.neighbours.push_back(across);
  }
  share.point_ids = renumber_locally(share.tets);  // (so that the healing rank welds without searching)
  const auto steiner = std::lower_bound(share.point_ids.begin(), share.point_ids.end(), place.steiner_to);
  for (auto it = steiner; it != share.point_ids.end(); ++it)
    share.points.push_back(band.steiner_points.at(static_cast<std::size_t>(*it - place.steiner_to)));
  return share;
}

// Those of `ids` that are cut vertices or caps' points with their planes (of any plane: a chain's
// tets decide which it uses), and the coordinates of all.
ChainSplit chain_split(const SplitSurface& split, const SurfaceMesh& input, const std::vector<Point3>& split_points,
                       const std::vector<int>& planes, const std::vector<std::int32_t>& triangles,
                       const std::vector<std::int32_t>& ids) {
  const SplitRanges ranges(split);
  ChainSplit chain;
  chain.planes = planes;
  chain.first_cut = ranges.first_cut, chain.first_cap = ranges.first_cap, chain.end_caps = ranges.end_caps;
  chain.point_ids = ids;
  chain.points.reserve(ids.size());
  for (const std::int32_t id : ids) {
    if (id < 0 || id >= ranges.end_caps) throw InternalError("a seam chain's split was asked for a point it has not");
    chain.points.push_back(split_points.at(static_cast<std::size_t>(id)));
    if (id >= ranges.first_cap) {
      chain.cap_points.push_back(id);
      chain.cap_point_plane.push_back(split.cap_point_plane[id - ranges.first_cap]);
    } else if (id >= ranges.first_cut) {
      chain.cut_vertices.push_back(id);
      chain.cut_vertex_plane.push_back(split.cut_vertex_plane[id - ranges.first_cut]);
    }
  }
  std::unordered_map<std::int32_t, std::int32_t> place;  // by input triangle
  for (auto t : triangles) {
    const std::int32_t parent = split.parent[t];
    const auto [it, fresh] = place.emplace(parent, static_cast<std::int32_t>(chain.input_triangles.size()));
    if (fresh) chain.input_triangles.push_back(input.triangles[parent]);
    chain.triangles.push_back(split.triangles[t]);
    chain.parent.push_back(it->second);
  }
  return chain;
}

ChainShares chain_shares(std::vector<ChainShare>&& shares, ChainSplit&& split) {
  ChainShares chain{std::move(shares), std::move(split)};
  order_shares(chain.shares);
  return chain;
}

std::vector<std::int32_t> band_tets_of(const ChainShares& chain) {
  std::vector<std::int32_t> tets;
  for (const ChainShare& share : chain.shares) tets.insert(tets.end(), share.band_tets.begin(), share.band_tets.end());
  return tets;
}

ChainBand weld_chain(ChainShares&& shares) {
  order_shares(shares.shares);  // (those a rank took from others come after rank 0's)
  ChainBand chain;
  const std::vector<std::int32_t> in_chain = weld_points(shares.shares, shares.split, chain);
  weld_tets(shares.shares, in_chain, SplitRanges(shares.split), chain);
  shares.shares.clear();
  cut_out_split(std::move(shares.split), chain);
  return chain;
}

std::vector<ChainParts> chain_parts(const TetMesh& band, const SplitSurface& split,
                                    const std::vector<std::vector<int>>& chains, const HealOptions& options) {
  const std::vector<int> chain_of_plane = chain_of_planes(split, chains);
  const std::vector<int> chain_of = chains_of_removed(split, options, chain_of_plane);
  const std::int32_t first = split.input_vertex_count;
  std::vector<std::int32_t> label(band.tets.size(), -1);
  std::vector<std::int32_t> layer;
  for (std::size_t t = 0; t < band.tets.size(); ++t)
    for (auto v : band.tets[t]) {
      const std::int64_t i = static_cast<std::int64_t>(v) - first;
      if (i >= 0 && i < static_cast<std::int64_t>(chain_of.size()) && chain_of[i] >= 0) {
        label[t] = chain_of[i];
        layer.push_back(static_cast<std::int32_t>(t));
        break;
      }
    }
  for (int depth = 0; depth < seam_band_spec(split, options).layers && !layer.empty(); ++depth) {
    std::vector<std::int32_t> next;
    for (auto t : layer)
      for (auto nb : band.neighbours[t])
        if (nb >= 0 && label[nb] < 0) label[nb] = label[t], next.push_back(nb);
    layer = std::move(next);
  }
  std::vector<ChainParts> parts(chains.size());
  for (std::size_t t = 0; t < label.size(); ++t)
    if (label[t] >= 0) parts[label[t]].tets.push_back(static_cast<std::int32_t>(t));
  std::vector<std::vector<std::int32_t>> triangles = chain_split_triangles(split, chains);
  for (std::size_t c = 0; c < parts.size(); ++c) parts[c].split_triangles = std::move(triangles[c]);
  return parts;
}

ChainBand cut_out_chain(const TetMesh& band, const SurfaceMesh& input, const SplitSurface& split,
                        const std::vector<int>& planes, ChainParts&& parts) {
  ChainBand chain;
  chain.band_tets = std::move(parts.tets);
  cut_out_tets(band, chain);
  const std::vector<std::int32_t> split_ids(
      chain.global_ids.begin(),
      std::lower_bound(chain.global_ids.begin(), chain.global_ids.end(), SplitRanges(split).end_caps));
  cut_out_split(chain_split(split, input, band.points, planes, parts.split_triangles, split_ids), chain);
  return chain;
}

HealedChain heal_chain(ChainBand&& chain, const HealOptions& options, const RegionMesher& mesher) {
  HealOptions whole_chain = options;
  whole_chain.drop_points = false;
  const double start = now_seconds();
  const auto old_points = static_cast<std::ptrdiff_t>(chain.mesh.points.size());
  HealedChain healed;
  try {
    healed.stats = heal_seams(chain.mesh, chain.input, chain.split, whole_chain, mesher);
  } catch (const MeshingError& error) {
    healed.failure = error.failure;
    return healed;
  }
  healed.global_ids = std::move(chain.global_ids);
  if (options.chain_band_tets) healed.band_tets = std::move(chain.band_tets);
  healed.new_points.assign(chain.mesh.points.begin() + old_points, chain.mesh.points.end());
  order_band_tets(chain.mesh);  // here, on the rank that healed it: not on rank 0, chain after chain
  healed.tets = std::move(chain.mesh.tets);
  healed.neighbours = std::move(chain.mesh.neighbours);
  healed.piece = std::move(chain.mesh.piece);
  chain.mesh = TetMesh();
  if (options.chain_links)
    healed.links = block_links(healed.tets, PointIds(), healed.neighbours, true, 0, {}, healed.label);
  healed.seconds = now_seconds() - start;
  return healed;
}

namespace {

// Throws InternalError unless the healed chain came with its neighbours, its pieces (when the
// band has them), its ids and, when asked, its links.
void check_healed_chain(const HealedChain& chain, bool pieces, bool links) {
  if (chain.kept_on >= 0) {
    if (!links || chain.used.size() != chain.global_ids.size() + chain.new_points.size())
      throw InternalError("a seam chain kept elsewhere came without its links or the points it uses");
    return;
  }
  const std::size_t tets = chain.tets.size();
  if (chain.neighbours.size() != tets || (pieces && chain.piece.size() != tets))
    throw InternalError("a healed chain of the seams came without its neighbours or pieces");
  if (links && chain.label.size() != tets) throw InternalError("a healed chain of the seams came without its links");
  if (tets > 0 && chain.global_ids.empty()) throw InternalError("a healed chain of the seams came without its ids");
}

// The chains' points and tets after the band's, in the band's ids; their neighbours too (moved
// past the band's tets), and, when `links`, their links (keys in the band's ids).
std::vector<BandChainLinks> append_healed_chains(TetMesh& band, std::vector<HealedChain>&& healed, bool links) {
  const bool pieces = band.piece.size() == band.tets.size();
  band.neighbours.resize(band.tets.size(), Tet{-1, -1, -1, -1});
  std::vector<BandChainLinks> chain_links(links ? healed.size() : 0);
  std::int32_t row = 0;  // in the band, the chains kept elsewhere counted
  for (std::size_t c = 0; c < healed.size(); ++c) {
    HealedChain& chain = healed[c];
    check_healed_chain(chain, pieces, links);
    const std::vector<std::int32_t>& global_ids = chain.global_ids;
    const auto old_points = static_cast<std::int64_t>(global_ids.size());
    const auto first_new = static_cast<std::int64_t>(band.points.size());
    const auto in_band = [&](std::int64_t v) {
      return static_cast<std::int32_t>(v < old_points ? global_ids[v] : first_new + (v - old_points));
    };
    const auto first_tet = static_cast<std::int32_t>(band.tets.size());
    band.points.insert(band.points.end(), chain.new_points.begin(), chain.new_points.end());
    if (chain.kept_on >= 0) {  // (its points and links only)
      for (auto& key : chain.links.keys)
        for (auto& v : key) v = in_band(v);
      BandChainLinks& kept = chain_links[c];
      kept.first_tet = row, kept.tets = chain.kept_tets, kept.links = std::move(chain.links);
      kept.kept_on = chain.kept_on, kept.kept_as = chain.kept_as;
      for (std::size_t v = 0; v < chain.used.size(); ++v)
        kept.band_ids.push_back(chain.used[v] ? in_band(static_cast<std::int64_t>(v)) : -1);
      row += chain.kept_tets;
      chain = HealedChain();
      continue;
    }
    for (std::size_t t = 0; t < chain.tets.size(); ++t) {
      Tet tet, across;
      for (int j = 0; j < 4; ++j) {
        tet[j] = static_cast<std::int32_t>(in_band(chain.tets[t][j]));
        const std::int32_t nb = chain.neighbours[t][j];
        across[j] = nb >= 0 ? first_tet + nb : -1;
      }
      band.tets.push_back(tet);
      band.neighbours.push_back(across);
    }
    if (pieces) band.piece.insert(band.piece.end(), chain.piece.begin(), chain.piece.end());
    const auto tets = static_cast<std::int32_t>(chain.tets.size());
    if (links) {
      for (auto& key : chain.links.keys)  // (the band's ids keep the chain's order: the keys stay sorted)
        for (auto& v : key) v = in_band(v);
      BandChainLinks& here = chain_links[c];
      here.first_tet = row, here.tets = tets, here.links = std::move(chain.links), here.label = std::move(chain.label);
    }
    row += tets;
    chain = HealedChain();
  }
  return chain_links;
}

}  // namespace

HealedChain kept_elsewhere(const HealedChain& chain, int rank, std::int32_t index) {
  HealedChain sent;
  sent.global_ids = chain.global_ids;
  sent.new_points = chain.new_points;
  sent.links = chain.links;
  sent.stats = chain.stats;
  sent.seconds = chain.seconds;
  sent.kept_on = rank, sent.kept_as = index;
  sent.kept_tets = static_cast<std::int32_t>(chain.tets.size());
  sent.used.assign(chain.global_ids.size() + chain.new_points.size(), 0);
  for (const Tet& t : chain.tets)
    for (const std::int32_t v : t) sent.used.at(static_cast<std::size_t>(v)) = 1;
  return sent;
}

void put_back_chains(TetMesh& band, const std::vector<std::vector<std::int32_t>>& chain_tets,
                     std::vector<HealedChain>&& healed) {
  if (healed.size() != chain_tets.size()) throw InternalError("seam healing lost a chain of the seams");
  const bool pieces = band.piece.size() == band.tets.size();
  std::vector<char> cut_out(band.tets.size(), 0);
  for (const std::vector<std::int32_t>& tets : chain_tets)
    for (auto t : tets) cut_out.at(static_cast<std::size_t>(t)) = 1;
  std::size_t kept = 0;
  for (std::size_t t = 0; t < band.tets.size(); ++t)
    if (!cut_out[t]) {
      band.tets[kept] = band.tets[t];
      if (pieces) band.piece[kept] = band.piece[t];
      ++kept;
    }
  band.tets.resize(kept);
  if (pieces) band.piece.resize(kept);
  std::vector<Tet>().swap(band.neighbours);
  append_healed_chains(band, std::move(healed), false);
  // (The tets kept meet the chains': connected anew.)
  band.neighbours = compute_neighbours(band.tets, band.points.size());
  order_band_tets(band);
}

std::vector<BandChainLinks> add_healed_chains(TetMesh& band, std::vector<HealedChain>&& healed, bool links) {
  if (!band.tets.empty()) throw InternalError("healed chains were added to a band that has tets");
  return append_healed_chains(band, std::move(healed), links);
}

void order_band_tets(TetMesh& band) {
  std::vector<Tet> keys(band.tets);
  for (Tet& key : keys) std::sort(key.begin(), key.end());
  std::vector<std::int32_t> order(band.tets.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::int32_t a, std::int32_t b) { return keys[a] < keys[b]; });
  std::vector<std::int32_t> place(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) place[order[i]] = static_cast<std::int32_t>(i);
  const bool pieces = band.piece.size() == band.tets.size();
  std::vector<Tet> tets(order.size()), neighbours(order.size());
  std::vector<std::int32_t> piece(pieces ? order.size() : 0);
  for (std::size_t i = 0; i < order.size(); ++i) {
    tets[i] = band.tets[order[i]];
    for (int j = 0; j < 4; ++j) {
      const std::int32_t nb = band.neighbours[order[i]][j];
      neighbours[i][j] = nb >= 0 ? place[nb] : -1;
    }
    if (pieces) piece[i] = band.piece[order[i]];
  }
  band.tets = std::move(tets);
  band.neighbours = std::move(neighbours);
  band.piece = std::move(piece);
}

}  // namespace partet
