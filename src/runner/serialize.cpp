#include "runner/serialize.hpp"

#include <algorithm>
#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>
#include <boost/serialization/array_wrapper.hpp>
#include <boost/serialization/string.hpp>
#include <cstdint>
#include <cstring>
#include <streambuf>

namespace partet {
namespace {

// Archives read from and write to memory directly: results can be hundreds of MB, and a
// stringstream would copy them once more.
class ReadBuffer : public std::streambuf {
 public:
  explicit ReadBuffer(std::string_view bytes) {
    char* begin = const_cast<char*>(bytes.data());
    setg(begin, begin, begin + bytes.size());
  }
};

class WriteBuffer : public std::streambuf {
 public:
  std::string bytes;

 protected:
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    bytes.append(s, static_cast<std::size_t>(n));
    return n;
  }
  int_type overflow(int_type c) override {
    if (!traits_type::eq_int_type(c, traits_type::eof())) bytes.push_back(traits_type::to_char_type(c));
    return traits_type::not_eof(c);
  }
};

// Flat vectors of fixed-size arrays go through as one contiguous block each.
template <class Archive, class T, std::size_t N>
void save_block(Archive& ar, const std::vector<std::array<T, N>>& v) {
  std::uint64_t n = v.size();
  ar << n;
  if (n) ar << boost::serialization::make_array(v.front().data(), n * N);
}
template <class Archive, class T, std::size_t N>
void load_block(Archive& ar, std::vector<std::array<T, N>>& v) {
  std::uint64_t n = 0;
  ar >> n;
  v.resize(n);
  if (n) ar >> boost::serialization::make_array(v.front().data(), n * N);
}
template <class Archive, class T>
void save_block(Archive& ar, const std::vector<T>& v) {
  std::uint64_t n = v.size();
  ar << n;
  if (n) ar << boost::serialization::make_array(v.data(), n);
}
template <class Archive, class T>
void load_block(Archive& ar, std::vector<T>& v) {
  std::uint64_t n = 0;
  ar >> n;
  v.resize(n);
  if (n) ar >> boost::serialization::make_array(v.data(), n);
}

constexpr unsigned kArchiveFlags = boost::archive::no_header;

// A healed chain's links in 32 bits: its keys are in its own ids and its faces are 4 * tet + j of
// its own tets, so an open face travels in 20 bytes instead of 36.
template <class Archive>
void save_chain_links(Archive& ar, const BlockLinks& links) {
  std::vector<Triangle> keys;
  keys.reserve(links.keys.size());
  for (const auto& key : links.keys) {
    if (key[2] > INT32_MAX || key[0] < 0) throw InternalError("a healed chain's open face is not in its own ids");
    keys.push_back(
        {static_cast<std::int32_t>(key[0]), static_cast<std::int32_t>(key[1]), static_cast<std::int32_t>(key[2])});
  }
  std::vector<std::uint32_t> faces;
  faces.reserve(links.face.size());
  for (const std::uint64_t face : links.face) {
    if (face > UINT32_MAX) throw InternalError("a healed chain has too many tets to send its links");
    faces.push_back(static_cast<std::uint32_t>(face));
  }
  save_block(ar, links.first_tet);
  save_block(ar, keys);
  save_block(ar, links.component);
  save_block(ar, faces);
}
template <class Archive>
void load_chain_links(Archive& ar, BlockLinks& links) {
  std::vector<Triangle> keys;
  std::vector<std::uint32_t> faces;
  load_block(ar, links.first_tet);
  load_block(ar, keys);
  load_block(ar, links.component);
  load_block(ar, faces);
  links.keys.reserve(keys.size());
  for (const Triangle& key : keys) links.keys.push_back({key[0], key[1], key[2]});
  links.face.assign(faces.begin(), faces.end());
}

// Runs save(archive) into a string reserved for `expected` bytes.
template <class Save>
std::string encode(std::size_t expected, Save save, std::string_view prefix = {}) {
  WriteBuffer buffer;
  buffer.bytes.reserve(expected + prefix.size());
  buffer.bytes.append(prefix);
  {
    boost::archive::binary_oarchive ar(buffer, kArchiveFlags);
    save(ar);
  }
  return std::move(buffer.bytes);
}

template <class T, class Load>
T decode(std::string_view bytes, Load load) {
  ReadBuffer buffer(bytes);
  boost::archive::binary_iarchive ar(buffer, kArchiveFlags);
  T value;
  load(ar, value);
  return value;
}

}  // namespace

namespace {

template <class Archive>
void save_piece(Archive& ar, const PieceSurface& piece) {
  std::int32_t index = piece.index;
  ar << index;
  save_block(ar, piece.global_ids);
  save_block(ar, piece.points);
  save_block(ar, piece.triangles);
}

template <class Archive>
void load_piece(Archive& ar, PieceSurface& piece) {
  std::int32_t index = 0;
  ar >> index;
  piece.index = index;
  load_block(ar, piece.global_ids);
  load_block(ar, piece.points);
  load_block(ar, piece.triangles);
}

std::size_t piece_bytes(const PieceSurface& piece) {
  return 64 + piece.global_ids.size() * 4 + piece.points.size() * 24 + piece.triangles.size() * 12;
}

}  // namespace

constexpr char kPieceTaskTag = 'P', kCapTaskTag = 'K', kChainTaskTag = 'H';

TaskKind task_kind(std::string_view bytes) {
  if (!bytes.empty() && bytes[0] == kPieceTaskTag) return TaskKind::piece;
  if (!bytes.empty() && bytes[0] == kCapTaskTag) return TaskKind::cap;
  if (!bytes.empty() && bytes[0] == kChainTaskTag) return TaskKind::chain;
  throw InternalError("a task has no valid tag");
}

std::string serialize_task(const PieceSurface& piece, const TetgenOptions& tetgen, const SplitOrder* split) {
  const std::size_t bytes =
      64 + piece_bytes(piece) + tetgen.quality.size() + tetgen.tolerance.size() + tetgen.optimization.size();
  return encode(
      bytes,
      [&](auto& ar) {
        save_piece(ar, piece);
        const std::int32_t seam_region = piece.seam_region ? 1 : 0, boundary_points = tetgen.boundary_points ? 1 : 0;
        ar << tetgen.quality << tetgen.tolerance << tetgen.optimization << seam_region << boundary_points;
        const std::int32_t order[7] = {split ? 1 : 0,
                                       split ? split->attempt : 0,
                                       split ? split->spec.input_vertex_count : 0,
                                       split ? split->spec.split_point_count : 0,
                                       split ? split->spec.first_removed : 0,
                                       split ? split->spec.end_removed : 0,
                                       split ? split->spec.layers : 0};
        ar << boost::serialization::make_array(order, 7);
      },
      std::string_view(&kPieceTaskTag, 1));
}

PieceSurface deserialize_task(std::string_view bytes, TetgenOptions& tetgen, std::optional<SplitOrder>* split) {
  if (task_kind(bytes) != TaskKind::piece) throw InternalError("a cap task was read as a piece");
  bytes.remove_prefix(1);
  return decode<PieceSurface>(bytes, [&](auto& ar, PieceSurface& piece) {
    load_piece(ar, piece);
    std::int32_t seam_region = 0, boundary_points = 0;
    ar >> tetgen.quality >> tetgen.tolerance >> tetgen.optimization >> seam_region >> boundary_points;
    piece.seam_region = seam_region != 0;
    tetgen.boundary_points = boundary_points != 0;
    std::int32_t order[7] = {};
    ar >> boost::serialization::make_array(order, 7);
    if (split && order[0]) *split = SplitOrder{BandSpec{order[2], order[3], order[4], order[5], order[6]}, order[1]};
  });
}

std::string serialize_cap_task(const CapBorder& border) {
  const std::size_t bytes = 64 + border.global_ids.size() * 28 + border.chords.size() * 8;
  return encode(
      bytes,
      [&](auto& ar) {
        const std::int32_t plane = border.plane;
        ar << plane << border.cut.offset << border.density;
        ar << boost::serialization::make_array(border.cut.normal.data(), 3);
        save_block(ar, border.global_ids);
        save_block(ar, border.points);
        save_block(ar, border.chords);
      },
      std::string_view(&kCapTaskTag, 1));
}

CapBorder deserialize_cap_task(std::string_view bytes) {
  if (task_kind(bytes) != TaskKind::cap) throw InternalError("a piece task was read as a cap");
  bytes.remove_prefix(1);
  return decode<CapBorder>(bytes, [](auto& ar, CapBorder& border) {
    std::int32_t plane = 0;
    ar >> plane >> border.cut.offset >> border.density;
    ar >> boost::serialization::make_array(border.cut.normal.data(), 3);
    border.plane = plane;
    load_block(ar, border.global_ids);
    load_block(ar, border.points);
    load_block(ar, border.chords);
  });
}

namespace {

std::string encode_result(const PieceTetMesh& result, std::string_view prefix) {
  const std::size_t expected = 64 + result.mesh.steiner_points.size() * 24 + result.mesh.tets.size() * 32;
  return encode(
      expected,
      [&](auto& ar) {
        std::int32_t index = result.index, count = result.surface_point_count;
        ar << index << count;
        save_block(ar, result.mesh.steiner_points);
        save_block(ar, result.mesh.tets);
        save_block(ar, result.mesh.neighbours);
      },
      prefix);
}

std::string encode_failure(const Failure& failure, std::string_view prefix) {
  return encode(
      64 + failure.message.size(),
      [&](auto& ar) {
        std::int32_t kind = static_cast<std::int32_t>(failure.kind), piece = failure.piece;
        std::vector<std::int32_t> planes(failure.planes.begin(), failure.planes.end());
        ar << kind << piece;
        save_block(ar, planes);
        ar << failure.message;
        save_block(ar, failure.faces);
      },
      prefix);
}

constexpr char kResultTag = 'R', kFailureTag = 'F', kBandTag = 'B';

template <class Archive>
void save_tet_block(Archive& ar, const TetBlock& block) {
  const std::uint8_t numbered = block.numbered;
  ar << numbered;
  if (numbered) {  // its compact ids (a bulk's: no table)
    if (block.ids.table) throw InternalError("a block of tets with a table of its ids cannot be sent");
    ar << block.ids.from << block.ids.shift;
  }
  save_block(ar, block.steiner_points);
  save_block(ar, block.tets);
  save_block(ar, block.neighbours);
  save_block(ar, block.rim);
}

template <class Archive>
void load_tet_block(Archive& ar, TetBlock& block) {
  std::uint8_t numbered = 0;
  ar >> numbered;
  block.numbered = numbered != 0;
  if (block.numbered) ar >> block.ids.from >> block.ids.shift;
  load_block(ar, block.steiner_points);
  load_block(ar, block.tets);
  load_block(ar, block.neighbours);
  load_block(ar, block.rim);
  block.in = true;
}

std::size_t tet_block_bytes(const TetBlock& block) {
  return 64 + block.steiner_points.size() * 24 + block.tets.size() * 32 + block.rim.size() * 8;
}

template <class Archive>
void save_crossings(Archive& ar, const std::vector<CapCrossing>& crossings) {
  std::vector<Tet> rows;  // the key's three vertices and the depth
  rows.reserve(crossings.size());
  for (const CapCrossing& c : crossings) rows.push_back({c.key.v[0], c.key.v[1], c.key.v[2], c.depth});
  save_block(ar, rows);
}

template <class Archive>
void load_crossings(Archive& ar, std::vector<CapCrossing>& crossings) {
  std::vector<Tet> rows;
  load_block(ar, rows);
  for (const Tet& c : rows) crossings.push_back({FaceKey({c[0], c[1], c[2]}), c[3]});
}

// A band part's links, when made: the vertices to remove by part (counts, then all of them), and
// the cap faces' keys with their parts.
template <class Archive>
void save_links(Archive& ar, const std::optional<BandPartLinks>& links) {
  const std::int32_t made = links ? 1 : 0;
  ar << made;
  if (!links) return;
  std::vector<std::int32_t> counts, removed;
  for (const auto& part : links->removed) {
    counts.push_back(static_cast<std::int32_t>(part.size()));
    removed.insert(removed.end(), part.begin(), part.end());
  }
  std::vector<Tet> faces;
  faces.reserve(links->cap_faces.size());
  for (const auto& [key, part] : links->cap_faces) faces.push_back({key.v[0], key.v[1], key.v[2], part});
  save_block(ar, counts);
  save_block(ar, removed);
  save_block(ar, faces);
  save_block(ar, links->tets);
}

template <class Archive>
void load_links(Archive& ar, std::optional<BandPartLinks>& links) {
  std::int32_t made = 0;
  ar >> made;
  links.reset();
  if (!made) return;
  std::vector<std::int32_t> counts, removed;
  std::vector<Tet> faces;
  load_block(ar, counts);
  load_block(ar, removed);
  load_block(ar, faces);
  links.emplace();
  load_block(ar, links->tets);
  if (links->tets.size() != counts.size()) throw InternalError("a band part's links count the tets of other parts");
  std::size_t at = 0;
  for (const std::int32_t count : counts) {
    if (count < 0 || removed.size() - at < static_cast<std::size_t>(count))
      throw InternalError("a band part's links hold fewer vertices than they count");
    links->removed.emplace_back(removed.begin() + static_cast<std::ptrdiff_t>(at),
                                removed.begin() + static_cast<std::ptrdiff_t>(at + static_cast<std::size_t>(count)));
    at += static_cast<std::size_t>(count);
  }
  for (const Tet& f : faces) {
    if (f[3] < 0 || static_cast<std::size_t>(f[3]) >= counts.size())
      throw InternalError("a band part's cap face names a part it does not have");
    links->cap_faces.emplace_back(FaceKey(Triangle{f[0], f[1], f[2]}), f[3]);
  }
}

std::string encode_band(const PieceBand& split, std::string_view prefix) {
  return encode(
      tet_block_bytes(split.band) + 64 + split.band_steiner.size() * 4 + split.band_tets.size() * 4 +
          split.band_split_points.size() * 4 + split.crossings.size() * 16 + split.cap_faces_outside.size() * 12,
      [&](auto& ar) {
        const std::int32_t index = split.index, first_steiner = split.first_steiner;
        const std::int64_t bulk_tets = split.bulk_tets, bulk_steiner = split.bulk_steiner_points;
        ar << index << first_steiner << bulk_tets << bulk_steiner;
        save_tet_block(ar, split.band);
        save_block(ar, split.band_steiner);
        save_block(ar, split.band_tets);
        save_crossings(ar, split.crossings);
        std::vector<Triangle> outside;
        for (const FaceKey& key : split.cap_faces_outside) outside.push_back({key.v[0], key.v[1], key.v[2]});
        save_block(ar, outside);
        save_links(ar, split.links);
        const std::int32_t kept = split.band_kept ? 1 : 0;
        const std::int64_t kept_tets = split.band_tet_count;
        ar << kept << kept_tets;
        save_block(ar, split.band_split_points);
      },
      prefix);
}

PieceBand deserialize_band(std::string_view bytes) {
  return decode<PieceBand>(bytes, [](auto& ar, PieceBand& split) {
    std::int32_t index = 0, first_steiner = 0;
    std::int64_t bulk_tets = 0, bulk_steiner = 0;
    ar >> index >> first_steiner >> bulk_tets >> bulk_steiner;
    split.index = index, split.first_steiner = first_steiner;
    split.bulk_tets = bulk_tets, split.bulk_steiner_points = bulk_steiner;
    load_tet_block(ar, split.band);
    load_block(ar, split.band_steiner);
    load_block(ar, split.band_tets);
    load_crossings(ar, split.crossings);
    std::vector<Triangle> outside;
    load_block(ar, outside);
    for (const Triangle& t : outside) split.cap_faces_outside.push_back(FaceKey(t));
    load_links(ar, split.links);
    std::int32_t kept = 0;
    std::int64_t kept_tets = 0;
    ar >> kept >> kept_tets;
    split.band_kept = kept != 0, split.band_tet_count = kept_tets;
    load_block(ar, split.band_split_points);
  });
}

PieceTetMesh deserialize_result(std::string_view bytes) {
  return decode<PieceTetMesh>(bytes, [](auto& ar, PieceTetMesh& result) {
    std::int32_t index = 0, count = 0;
    ar >> index >> count;
    result.index = index;
    result.surface_point_count = count;
    load_block(ar, result.mesh.steiner_points);
    load_block(ar, result.mesh.tets);
    load_block(ar, result.mesh.neighbours);
  });
}

Failure deserialize_failure(std::string_view bytes) {
  return decode<Failure>(bytes, [](auto& ar, Failure& failure) {
    std::int32_t kind = 0, piece = 0;
    std::vector<std::int32_t> planes;
    ar >> kind >> piece;
    load_block(ar, planes);
    ar >> failure.message;
    load_block(ar, failure.faces);
    failure.kind = static_cast<FailureKind>(kind);
    failure.piece = piece;
    failure.planes.assign(planes.begin(), planes.end());
  });
}

}  // namespace

std::string serialize_outcome(const PieceOutcome& outcome) {
  char prefix[1 + 2 * sizeof(double)];
  prefix[0] = outcome.failure ? kFailureTag : outcome.band ? kBandTag : kResultTag;
  std::memcpy(prefix + 1, &outcome.seconds, sizeof(double));
  std::memcpy(prefix + 1 + sizeof(double), &outcome.memory_mb, sizeof(double));
  const std::string_view head(prefix, sizeof prefix);
  if (outcome.failure) return encode_failure(*outcome.failure, head);
  return outcome.band ? encode_band(*outcome.band, head) : encode_result(outcome.result, head);
}

std::string serialize_band_to_grow(const BandToGrow& band) {
  return encode(tet_block_bytes(band.band) + 64 + band.band_steiner.size() * 4 + band.band_tets.size() * 4 +
                    band.crossings.size() * 16,
                [&](auto& ar) {
                  const std::int32_t index = band.index;
                  std::vector<std::int32_t> spec = {band.spec.input_vertex_count, band.spec.split_point_count,
                                                    band.spec.first_removed, band.spec.end_removed, band.spec.layers};
                  ar << index;
                  save_block(ar, spec);
                  save_tet_block(ar, band.band);
                  save_block(ar, band.band_steiner);
                  save_block(ar, band.band_tets);
                  save_crossings(ar, band.crossings);
                  const std::int32_t kept = band.band_kept ? 1 : 0;
                  ar << kept;
                });
}

BandToGrow deserialize_band_to_grow(std::string_view bytes) {
  return decode<BandToGrow>(bytes, [](auto& ar, BandToGrow& band) {
    std::int32_t index = 0;
    std::vector<std::int32_t> spec;
    ar >> index;
    band.index = index;
    load_block(ar, spec);
    if (spec.size() != 5) throw InternalError("a band to grow came without its band's spec");
    band.spec = BandSpec{spec[0], spec[1], spec[2], spec[3], spec[4]};
    load_tet_block(ar, band.band);
    load_block(ar, band.band_steiner);
    load_block(ar, band.band_tets);
    load_crossings(ar, band.crossings);
    std::int32_t kept = 0;
    ar >> kept;
    band.band_kept = kept != 0;
  });
}

std::string serialize_grown_band(const PieceBand& grown) {
  if (grown.bulk.in) throw InternalError("a grown band travels without its bulk");
  return encode_band(grown, {});
}

PieceBand deserialize_grown_band(std::string_view bytes) { return deserialize_band(bytes); }

std::string serialize_share_plan(const std::vector<BandPartPlan>& plans, const std::vector<int>& order,
                                 const std::vector<int>& healers) {
  return encode(64 + plans.size() * 64 + order.size() * 8, [&](auto& ar) {
    save_block(ar, order);
    save_block(ar, healers);
    const std::uint64_t count = plans.size();
    ar << count;
    for (const BandPartPlan& plan : plans) {
      const std::vector<std::int32_t> place = {plan.place.piece, plan.place.first_tet, plan.place.steiner_from,
                                               plan.place.steiner_to};
      save_block(ar, place);
      save_block(ar, plan.chain_of_part);
    }
  });
}

void deserialize_share_plan(std::string_view bytes, std::vector<BandPartPlan>& plans, std::vector<int>& order,
                            std::vector<int>& healers) {
  plans = decode<std::vector<BandPartPlan>>(bytes, [&](auto& ar, std::vector<BandPartPlan>& all) {
    load_block(ar, order);
    load_block(ar, healers);
    const auto chains = static_cast<int>(healers.size());
    if (std::any_of(order.begin(), order.end(), [&](int c) { return c < 0 || c >= chains; }))
      throw InternalError("the seam chains' plan names a chain without a healing rank");
    std::uint64_t count = 0;
    ar >> count;
    for (std::uint64_t i = 0; i < count; ++i) {
      std::vector<std::int32_t> place;
      BandPartPlan& plan = all.emplace_back();
      load_block(ar, place);
      if (place.size() != 4) throw InternalError("a band part's plan came without its place");
      plan.place = BandPartPlace{place[0], place[1], place[2], place[3]};
      load_block(ar, plan.chain_of_part);
    }
  });
}

namespace {

std::size_t chain_share_bytes(const std::vector<ChainShare>& shares) {
  std::size_t bytes = 64;
  for (const ChainShare& share : shares) bytes += 64 + share.tets.size() * 36 + share.points.size() * 28;
  return bytes;
}

template <class Archive>
void save_chain_shares(Archive& ar, const std::vector<ChainShare>& shares) {
  const std::uint64_t count = shares.size();
  ar << count;
  for (const ChainShare& share : shares) {
    const std::int32_t chain = share.chain, piece = share.piece;
    ar << chain << piece;
    save_block(ar, share.band_tets);
    save_block(ar, share.tets);
    save_block(ar, share.neighbours);
    save_block(ar, share.point_ids);
    save_block(ar, share.points);
  }
}

template <class Archive>
void load_chain_shares(Archive& ar, std::vector<ChainShare>& shares) {
  std::uint64_t count = 0;
  ar >> count;
  for (std::uint64_t i = 0; i < count; ++i) {
    ChainShare& share = shares.emplace_back();
    std::int32_t chain = 0, piece = 0;
    ar >> chain >> piece;
    share.chain = chain, share.piece = piece;
    load_block(ar, share.band_tets);
    load_block(ar, share.tets);
    load_block(ar, share.neighbours);
    load_block(ar, share.point_ids);
    load_block(ar, share.points);
    if (share.neighbours.size() != share.tets.size() || share.band_tets.size() != share.tets.size() ||
        share.points.size() > share.point_ids.size())
      throw InternalError("a seam chain's share came with arrays of different lengths");
  }
}

}  // namespace

std::string serialize_chain_shares(const std::vector<ChainShare>& shares) {
  return encode(chain_share_bytes(shares), [&](auto& ar) { save_chain_shares(ar, shares); });
}

std::vector<ChainShare> deserialize_chain_shares(std::string_view bytes) {
  return decode<std::vector<ChainShare>>(
      bytes, [](auto& ar, std::vector<ChainShare>& shares) { load_chain_shares(ar, shares); });
}

std::string serialize_block(const TetBlock& block) {
  return encode(tet_block_bytes(block), [&](auto& ar) { save_tet_block(ar, block); });
}

TetBlock deserialize_block(std::string_view bytes) {
  return decode<TetBlock>(bytes, [](auto& ar, TetBlock& block) { load_tet_block(ar, block); });
}

// The split surface's points that go are the same for every bulk: they travel once.
std::string serialize_bulk_shares(const std::vector<BulkShare>& shares) {
  static const std::vector<std::int32_t> none;
  const std::vector<std::int32_t>& dropped_split = shares.empty() ? none : *shares[0].numbering.dropped_split;
  for (const BulkShare& s : shares)
    if (s.numbering.dropped_split != shares[0].numbering.dropped_split && *s.numbering.dropped_split != dropped_split)
      throw InternalError("the bulks' shares of the numbering drop different split points");
  return encode(64 + 4 * dropped_split.size() + shares.size() * 64, [&](auto& ar) {
    const std::uint64_t count = shares.size();
    ar << count;
    save_block(ar, dropped_split);
    for (const BulkShare& s : shares) {
      ar << s.piece << s.first_steiner << s.numbering.split_points << s.numbering.first_steiner;
      save_block(ar, s.numbering.dropped_steiner);
    }
  });
}

std::vector<BulkShare> deserialize_bulk_shares(std::string_view bytes) {
  return decode<std::vector<BulkShare>>(bytes, [](auto& ar, std::vector<BulkShare>& shares) {
    std::uint64_t count = 0;
    ar >> count;
    std::vector<std::int32_t> dropped_split;
    load_block(ar, dropped_split);
    const auto shared = std::make_shared<const std::vector<std::int32_t>>(std::move(dropped_split));
    shares.resize(count);
    for (BulkShare& s : shares) {
      ar >> s.piece >> s.first_steiner >> s.numbering.split_points >> s.numbering.first_steiner;
      s.numbering.dropped_split = shared;
      load_block(ar, s.numbering.dropped_steiner);
    }
  });
}

std::string serialize_bulk_links(const std::vector<std::pair<int, BlockLinks>>& links) {
  std::size_t expected = 64;
  for (const auto& [piece, l] : links) expected += 32 + 4 * l.first_tet.size() + 40 * l.keys.size();
  return encode(expected, [&](auto& ar) {
    const std::uint64_t count = links.size();
    ar << count;
    for (const auto& [piece, l] : links) {
      const std::int32_t p = piece;
      ar << p;
      save_block(ar, l.first_tet);
      save_block(ar, l.keys);
      save_block(ar, l.component);
      save_block(ar, l.face);
    }
  });
}

std::vector<std::pair<int, BlockLinks>> deserialize_bulk_links(std::string_view bytes) {
  auto links = decode<std::vector<std::pair<int, BlockLinks>>>(bytes, [](auto& ar, auto& all) {
    std::uint64_t count = 0;
    ar >> count;
    all.resize(count);
    for (auto& [piece, l] : all) {
      std::int32_t p = 0;
      ar >> p;
      piece = p;
      load_block(ar, l.first_tet);
      load_block(ar, l.keys);
      load_block(ar, l.component);
      load_block(ar, l.face);
    }
  });
  for (const auto& [piece, l] : links)
    if (l.keys.size() != l.component.size() || l.keys.size() != l.face.size())
      throw InternalError("malformed links of the bulk of piece " + std::to_string(piece));
  return links;
}

std::string serialize_placement(const std::vector<SpreadBulk>& bulks) {
  return encode(64 + bulks.size() * 64, [&](auto& ar) {
    const std::uint64_t count = bulks.size();
    ar << count;
    for (const SpreadBulk& b : bulks) {
      const std::int32_t piece = b.piece;
      ar << piece << b.first_point << b.points << b.first_tet << b.tets;
      save_block(ar, b.solid);
    }
  });
}

std::vector<SpreadBulk> deserialize_placement(std::string_view bytes) {
  return decode<std::vector<SpreadBulk>>(bytes, [](auto& ar, std::vector<SpreadBulk>& bulks) {
    std::uint64_t count = 0;
    ar >> count;
    bulks.resize(count);
    for (SpreadBulk& b : bulks) {
      std::int32_t piece = 0;
      ar >> piece >> b.first_point >> b.points >> b.first_tet >> b.tets;
      b.piece = piece;
      load_block(ar, b.solid);
    }
  });
}

std::string serialize_band_runs(const std::vector<BandRun>& runs, bool elsewhere_only) {
  std::size_t bytes = 64;
  for (const BandRun& run : runs) bytes += 64 + run.solid.size() * 4 + run.point_ids.size() * 8;
  return encode(bytes, [&](auto& ar) {
    std::uint64_t count = 0;
    for (const BandRun& run : runs) count += !elsewhere_only || run.rank != 0;
    ar << count;
    for (const BandRun& run : runs) {
      if (elsewhere_only && run.rank == 0) continue;
      const std::int32_t head[2] = {run.chain, run.rank};
      ar << boost::serialization::make_array(head, 2) << run.first_row << run.tets << run.first_here;
      save_block(ar, run.solid);
      save_block(ar, run.point_ids);
    }
  });
}

std::vector<BandRun> deserialize_band_runs(std::string_view bytes) {
  return decode<std::vector<BandRun>>(bytes, [](auto& ar, std::vector<BandRun>& runs) {
    std::uint64_t count = 0;
    ar >> count;
    runs.resize(count);
    for (BandRun& run : runs) {
      std::int32_t head[2] = {};
      ar >> boost::serialization::make_array(head, 2) >> run.first_row >> run.tets >> run.first_here;
      run.chain = head[0], run.rank = head[1];
      load_block(ar, run.solid);
      load_block(ar, run.point_ids);
    }
  });
}

namespace {
constexpr char kCapShapeTag = 'C', kCapFailureTag = 'E';
constexpr std::size_t kCapHead = 1 + sizeof(double);
}  // namespace

std::string serialize_cap_outcome(const CapOutcome& outcome) {
  char prefix[kCapHead];
  prefix[0] = outcome.failure ? kCapFailureTag : kCapShapeTag;
  std::memcpy(prefix + 1, &outcome.seconds, sizeof(double));
  const std::string_view head(prefix, sizeof prefix);
  if (outcome.failure) return encode_failure(*outcome.failure, head);
  const CapShape& shape = outcome.shape;
  return encode(
      64 + shape.interior_points.size() * 24 + shape.triangles.size() * 12,
      [&](auto& ar) {
        const std::int32_t plane = shape.plane;
        ar << plane;
        save_block(ar, shape.interior_points);
        save_block(ar, shape.triangles);
      },
      head);
}

bool is_cap_outcome(std::string_view reply) {
  return !reply.empty() && (reply[0] == kCapShapeTag || reply[0] == kCapFailureTag);
}

CapOutcome deserialize_cap_outcome(std::string_view bytes) {
  if (bytes.size() < kCapHead || !is_cap_outcome(bytes)) throw InternalError("a cap reply has no valid tag");
  CapOutcome outcome;
  std::memcpy(&outcome.seconds, bytes.data() + 1, sizeof(double));
  if (bytes[0] == kCapFailureTag) {
    outcome.failure = deserialize_failure(bytes.substr(kCapHead));
    return outcome;
  }
  outcome.shape = decode<CapShape>(bytes.substr(kCapHead), [](auto& ar, CapShape& shape) {
    std::int32_t plane = 0;
    ar >> plane;
    shape.plane = plane;
    load_block(ar, shape.interior_points);
    load_block(ar, shape.triangles);
  });
  return outcome;
}

namespace {
constexpr std::size_t kHead = 1 + 2 * sizeof(double);
}  // namespace

bool is_result_reply(std::string_view bytes) { return bytes.size() > kHead && bytes[0] == kResultTag; }

void set_reply_figures(std::string& bytes, double seconds, double memory_mb) {
  if (bytes.size() < kHead) throw InternalError("a meshing reply is too short");
  std::memcpy(bytes.data() + 1, &seconds, sizeof(double));
  std::memcpy(bytes.data() + 1 + sizeof(double), &memory_mb, sizeof(double));
}

PieceOutcome deserialize_outcome(std::string_view bytes) {
  if (bytes.size() < kHead || (bytes[0] != kResultTag && bytes[0] != kFailureTag && bytes[0] != kBandTag))
    throw InternalError("a meshing reply has no valid tag");
  PieceOutcome outcome;
  std::memcpy(&outcome.seconds, bytes.data() + 1, sizeof(double));
  std::memcpy(&outcome.memory_mb, bytes.data() + 1 + sizeof(double), sizeof(double));
  if (bytes[0] == kResultTag)
    outcome.result = deserialize_result(bytes.substr(kHead));
  else if (bytes[0] == kBandTag)
    outcome.band = deserialize_band(bytes.substr(kHead));
  else
    outcome.failure = deserialize_failure(bytes.substr(kHead));
  return outcome;
}

}  // namespace partet

namespace partet {
namespace {
constexpr char kChainHealedTag = 'L', kChainFailureTag = 'M', kChainKeptTag = 'W';

template <class Archive>
void save_stats(Archive& ar, const SeamStats& stats) {
  std::int64_t figures[6] = {
      stats.cut_vertices_removed, stats.cap_points_removed, stats.regions, stats.tets_in, stats.tets_out, stats.chains};
  ar << boost::serialization::make_array(figures, 6);
}

template <class Archive>
void load_stats(Archive& ar, SeamStats& stats) {
  std::int64_t figures[6] = {};
  ar >> boost::serialization::make_array(figures, 6);
  stats.cut_vertices_removed = figures[0];
  stats.cap_points_removed = figures[1];
  stats.regions = figures[2];
  stats.tets_in = figures[3];
  stats.tets_out = figures[4];
  stats.chains = figures[5];
}
}  // namespace

namespace {

template <class Archive>
void save_chain_split(Archive& ar, const ChainSplit& split) {
  const std::int32_t ranges[3] = {split.first_cut, split.first_cap, split.end_caps};
  ar << boost::serialization::make_array(ranges, 3);
  const std::vector<std::int32_t> planes(split.planes.begin(), split.planes.end());
  save_block(ar, planes);
  save_block(ar, split.point_ids);
  save_block(ar, split.points);
  save_block(ar, split.cut_vertices);
  save_block(ar, split.cut_vertex_plane);
  save_block(ar, split.cap_points);
  save_block(ar, split.cap_point_plane);
  save_block(ar, split.triangles);
  save_block(ar, split.parent);
  save_block(ar, split.input_triangles);
}

template <class Archive>
void load_chain_split(Archive& ar, ChainSplit& split) {
  std::int32_t ranges[3] = {};
  ar >> boost::serialization::make_array(ranges, 3);
  split.first_cut = ranges[0], split.first_cap = ranges[1], split.end_caps = ranges[2];
  std::vector<std::int32_t> planes;
  load_block(ar, planes);
  split.planes.assign(planes.begin(), planes.end());
  load_block(ar, split.point_ids);
  load_block(ar, split.points);
  load_block(ar, split.cut_vertices);
  load_block(ar, split.cut_vertex_plane);
  load_block(ar, split.cap_points);
  load_block(ar, split.cap_point_plane);
  load_block(ar, split.triangles);
  load_block(ar, split.parent);
  load_block(ar, split.input_triangles);
  const auto parents = static_cast<std::int32_t>(split.input_triangles.size());
  const bool parents_known =
      std::all_of(split.parent.begin(), split.parent.end(), [&](std::int32_t p) { return p >= 0 && p < parents; });
  if (split.point_ids.size() != split.points.size() || split.cut_vertices.size() != split.cut_vertex_plane.size() ||
      split.cap_points.size() != split.cap_point_plane.size() || split.parent.size() != split.triangles.size() ||
      !parents_known)
    throw InternalError("a seam chain's split came with arrays that do not match");
}

}  // namespace

std::string serialize_chain_task(const ChainTask& task) {
  const ChainSplit& split = task.chain.split;
  const std::size_t bytes = 256 + chain_share_bytes(task.chain.shares) + split.triangles.size() * 28 +
                            split.point_ids.size() * 28 + (split.cut_vertices.size() + split.cap_points.size()) * 8;
  return encode(
      bytes,
      [&](auto& ar) {
        const std::int32_t head[8] = {task.index,
                                      task.heal.remove_cap_points,
                                      task.heal.layers,
                                      task.tetgen.boundary_points,
                                      task.heal.chain_links,
                                      task.heal.chain_band_tets,
                                      task.shares_of,
                                      task.heal.keep_healed};
        ar << boost::serialization::make_array(head, 8);
        ar << task.tetgen.quality << task.tetgen.tolerance << task.tetgen.optimization << task.failure;
        save_block(ar, task.share_ranks);
        save_chain_split(ar, split);
        save_chain_shares(ar, task.chain.shares);
      },
      std::string_view(&kChainTaskTag, 1));
}

ChainTask deserialize_chain_task(std::string_view bytes) {
  if (task_kind(bytes) != TaskKind::chain) throw InternalError("a task was read as a chain of the seams");
  bytes.remove_prefix(1);
  return decode<ChainTask>(bytes, [](auto& ar, ChainTask& task) {
    std::int32_t head[8] = {};
    ar >> boost::serialization::make_array(head, 8);
    task.index = head[0];
    task.heal.remove_cap_points = head[1] != 0;
    task.heal.layers = head[2];
    task.tetgen.boundary_points = head[3] != 0;
    task.heal.chain_links = head[4] != 0;
    task.heal.chain_band_tets = head[5] != 0;
    task.shares_of = head[6];
    task.heal.keep_healed = head[7] != 0;
    ar >> task.tetgen.quality >> task.tetgen.tolerance >> task.tetgen.optimization >> task.failure;
    load_block(ar, task.share_ranks);
    load_chain_split(ar, task.chain.split);
    load_chain_shares(ar, task.chain.shares);
  });
}

std::string serialize_chain_outcome(std::int32_t index, const HealedChain& healed) {
  const char tag = healed.failure ? kChainFailureTag : healed.kept_on >= 0 ? kChainKeptTag : kChainHealedTag;
  if (healed.failure) {
    const std::string failure = encode_failure(*healed.failure, {});
    return encode(
        64 + failure.size(), [&](auto& ar) { ar << index << failure; }, std::string_view(&tag, 1));
  }
  return encode(
      160 + (healed.global_ids.size() + healed.band_tets.size()) * 4 + healed.new_points.size() * 24 +
          healed.tets.size() * 40 + healed.links.first_tet.size() * 4 + healed.links.keys.size() * 20,
      [&](auto& ar) {
        ar << index << healed.seconds;
        save_stats(ar, healed.stats);
        save_block(ar, healed.global_ids);
        save_block(ar, healed.new_points);
        save_block(ar, healed.tets);
        save_block(ar, healed.neighbours);
        save_block(ar, healed.piece);
        save_block(ar, healed.label);
        save_block(ar, healed.band_tets);
        save_chain_links(ar, healed.links);
        if (healed.kept_on < 0) return;
        ar << healed.kept_on << healed.kept_as << healed.kept_tets;
        save_block(ar, healed.used);
      },
      std::string_view(&tag, 1));
}

bool is_chain_outcome(std::string_view reply) {
  return !reply.empty() && (reply[0] == kChainHealedTag || reply[0] == kChainFailureTag || reply[0] == kChainKeptTag);
}

HealedChain deserialize_chain_outcome(std::string_view bytes, std::int32_t& index) {
  if (!is_chain_outcome(bytes)) throw InternalError("a reply was read as a chain of the seams");
  const bool failed = bytes[0] == kChainFailureTag, kept = bytes[0] == kChainKeptTag;
  bytes.remove_prefix(1);
  HealedChain chain = decode<HealedChain>(bytes, [&](auto& ar, HealedChain& healed) {
    ar >> index;
    if (failed) {
      std::string failure;
      ar >> failure;
      healed.failure = deserialize_failure(failure);
      return;
    }
    ar >> healed.seconds;
    load_stats(ar, healed.stats);
    load_block(ar, healed.global_ids);
    load_block(ar, healed.new_points);
    load_block(ar, healed.tets);
    load_block(ar, healed.neighbours);
    load_block(ar, healed.piece);
    load_block(ar, healed.label);
    load_block(ar, healed.band_tets);
    load_chain_links(ar, healed.links);
    if (!kept) return;
    ar >> healed.kept_on >> healed.kept_as >> healed.kept_tets;
    load_block(ar, healed.used);
  });
  const BlockLinks& links = chain.links;
  const auto points = static_cast<std::int64_t>(chain.global_ids.size() + chain.new_points.size());
  const bool points_known = std::all_of(chain.tets.begin(), chain.tets.end(), [&](const Tet& t) {
    return std::all_of(t.begin(), t.end(), [&](std::int32_t v) { return v >= 0 && v < points; });
  });
  if (links.keys.size() != links.component.size() || links.keys.size() != links.face.size() ||
      chain.neighbours.size() != chain.tets.size() ||
      (!chain.label.empty() && chain.label.size() != chain.tets.size()) || !points_known ||
      (kept && (chain.kept_on < 0 || chain.used.size() != static_cast<std::size_t>(points))))
    throw InternalError("malformed healed chain " + std::to_string(index) + " of the seams");
  return chain;
}

}  // namespace partet
