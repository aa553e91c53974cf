#include "partet/serialize.hpp"

#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>
#include <boost/serialization/array_wrapper.hpp>
#include <sstream>

namespace partet {
namespace {

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

}  // namespace

std::string serialize_piece(const PieceSurface& piece) {
  std::ostringstream os;
  {
    boost::archive::binary_oarchive ar(os, kArchiveFlags);
    std::int32_t index = piece.index;
    ar << index;
    save_block(ar, piece.global_ids);
    save_block(ar, piece.points);
    save_block(ar, piece.triangles);
  }
  return std::move(os).str();
}

PieceSurface deserialize_piece(const std::string& bytes) {
  std::istringstream is(bytes);
  boost::archive::binary_iarchive ar(is, kArchiveFlags);
  PieceSurface piece;
  std::int32_t index = 0;
  ar >> index;
  piece.index = index;
  load_block(ar, piece.global_ids);
  load_block(ar, piece.points);
  load_block(ar, piece.triangles);
  return piece;
}

std::string serialize_result(const PieceTetMesh& result) {
  std::ostringstream os;
  {
    boost::archive::binary_oarchive ar(os, kArchiveFlags);
    std::int32_t index = result.index, count = result.surface_point_count;
    ar << index << count;
    save_block(ar, result.mesh.steiner_points);
    save_block(ar, result.mesh.tets);
    save_block(ar, result.mesh.neighbours);
  }
  return std::move(os).str();
}

PieceTetMesh deserialize_result(const std::string& bytes) {
  std::istringstream is(bytes);
  boost::archive::binary_iarchive ar(is, kArchiveFlags);
  PieceTetMesh result;
  std::int32_t index = 0, count = 0;
  ar >> index >> count;
  result.index = index;
  result.surface_point_count = count;
  load_block(ar, result.mesh.steiner_points);
  load_block(ar, result.mesh.tets);
  load_block(ar, result.mesh.neighbours);
  return result;
}

}  // namespace partet
