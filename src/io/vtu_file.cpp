#include "io/vtu_file.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "common/parallel.hpp"
#include "common/write_all.hpp"
#include "partet/errors.hpp"

namespace partet {
namespace {

// VTK's compression blocks, compressed kBatch at a time on every usable CPU.
constexpr std::size_t kBlock = std::size_t(1) << 20;
constexpr std::size_t kBatch = 16;
// The offsets in the XML head are written last, each in this many characters (padded after the
// attribute with spaces), so the head keeps its length.
constexpr std::size_t kOffsetWidth = 20;

struct ArrayInfo {
  const char* name;
  const char* type;
  int components;
  std::uint64_t bytes_per_item;
  bool per_point;
};

// By VtuArray, in its order.
constexpr ArrayInfo kArrays[] = {{"Points", "Float64", 3, 24, true},     {"connectivity", "Int64", 1, 32, false},
                                 {"offsets", "Int64", 1, 8, false},      {"types", "UInt8", 1, 1, false},
                                 {"piece", "Int32", 1, 4, false},        {"region", "Int32", 1, 4, false},
                                 {"GlobalPointIds", "Int64", 1, 8, true}};

ArrayInfo info_of(VtuArray array) { return kArrays[static_cast<std::size_t>(array)]; }

std::uint64_t blocks_of(std::uint64_t bytes) { return (bytes + kBlock - 1) / kBlock; }

}  // namespace

VtuFileWriter::VtuFileWriter(const std::string& path, const std::string& shown, std::uint64_t points,
                             std::uint64_t cells, bool global_ids)
    : path_(path),
      shown_(shown),
      points_(points),
      cells_(cells),
      global_ids_(global_ids),
      out_(path, shown, /*must_exist=*/true),
      batch_(kBatch * kBlock) {
  const std::string head = this->head();  // its offsets not yet known: the same length
  put(head.data(), head.size());
  data_start_ = position_;
}

VtuFileWriter::~VtuFileWriter() = default;

std::string VtuFileWriter::head() const {
  const auto data_array = [&](VtuArray which) {
    const ArrayInfo a = info_of(which);
    const auto i = static_cast<std::size_t>(which);
    const std::string offset = std::to_string(i < begins_.size() ? begins_[i] : 0);
    return std::string("<DataArray type=\"") + a.type + "\" Name=\"" + a.name + "\" NumberOfComponents=\"" +
           std::to_string(a.components) + "\" format=\"appended\" offset=\"" + offset + "\"" +
           std::string(kOffsetWidth - offset.size(), ' ') + "/>\n";
  };
  return "<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" "
         "compressor=\"vtkZLibDataCompressor\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"" +
         std::to_string(points_) + "\" NumberOfCells=\"" + std::to_string(cells_) + "\">\n" +
         (global_ids_
              ? "<PointData GlobalIds=\"GlobalPointIds\">\n" + data_array(VtuArray::global_ids) + "</PointData>\n"
              : "") +
         "<Points>\n" + data_array(VtuArray::points) + "</Points>\n<Cells>\n" + data_array(VtuArray::connectivity) +
         data_array(VtuArray::offsets) + data_array(VtuArray::types) + "</Cells>\n<CellData Scalars=\"piece\">\n" +
         data_array(VtuArray::piece) + data_array(VtuArray::region) +
         "</CellData>\n</Piece>\n</UnstructuredGrid>\n<AppendedData encoding=\"raw\">\n_";
}

void VtuFileWriter::put(const void* data, std::size_t size) {
  out_.bytes(data, size);
  position_ += size;
}

void VtuFileWriter::array(VtuArray which, const std::function<void(ByteSink& out)>& fill) {
  if (static_cast<std::size_t>(which) != begins_.size() || (which == VtuArray::global_ids && !global_ids_))
    throw InternalError("the arrays of '" + shown_ + "' are written out of order");
  const ArrayInfo info = info_of(which);
  expected_ = (info.per_point ? points_ : cells_) * info.bytes_per_item, received_ = 0, batch_used_ = 0;
  begins_.push_back(position_ - data_start_);
  // The header: its block sizes are written when they are known (close).
  const std::uint64_t blocks = blocks_of(expected_);
  headers_.push_back({blocks, kBlock, blocks == 0 ? 0 : expected_ - (blocks - 1) * kBlock});
  const std::vector<std::uint64_t> kept(3 + blocks, 0);
  put(kept.data(), kept.size() * sizeof(std::uint64_t));
  fill(*this);
  compress_batch();
  if (received_ != expected_)
    throw OutputError("cannot write '" + shown_ + "': its " + info.name + " array has " + std::to_string(received_) +
                      " bytes, not " + std::to_string(expected_));
}

void VtuFileWriter::cell_layout() {
  // Made a block at a time (one call per cell was 33M calls per array at 22M faces).
  constexpr std::uint64_t kCells = kBlock / sizeof(std::int64_t);
  array(VtuArray::offsets, [&](ByteSink& out) {
    std::vector<std::int64_t> offsets;
    for (std::uint64_t first = 0; first < cells_; first += kCells) {
      offsets.clear();
      for (std::uint64_t c = first; c < std::min(cells_, first + kCells); ++c)
        offsets.push_back(static_cast<std::int64_t>(4 * (c + 1)));
      out.bytes(offsets.data(), offsets.size() * sizeof(std::int64_t));
    }
  });
  array(VtuArray::types, [&](ByteSink& out) {
    const std::vector<std::uint8_t> tetra(std::min(cells_, kCells), 10);  // VTK_TETRA
    for (std::uint64_t first = 0; first < cells_; first += kCells)
      out.bytes(tetra.data(), std::min(cells_ - first, kCells));
  });
}

void VtuFileWriter::bytes(const void* data, std::size_t size) {
  const auto* p = static_cast<const unsigned char*>(data);
  received_ += size;
  if (received_ > expected_) return;  // too many: array() fails the write
  while (size > 0) {
    const std::size_t n = std::min(size, batch_.size() - batch_used_);
    std::memcpy(batch_.data() + batch_used_, p, n);
    batch_used_ += n, p += n, size -= n;
    if (batch_used_ == batch_.size()) compress_batch();
  }
}

// Compresses the raw bytes gathered (whole blocks, and the array's last) and writes them.
void VtuFileWriter::compress_batch() {
  const std::size_t blocks = (batch_used_ + kBlock - 1) / kBlock;
  std::vector<std::vector<unsigned char>> packed(blocks);
  parallel_for(blocks, usable_cpus(), [&](std::size_t b) {
    const std::size_t length = std::min(kBlock, batch_used_ - b * kBlock);
    uLongf size = compressBound(static_cast<uLong>(length));
    packed[b].resize(size);
    if (compress2(packed[b].data(), &size, batch_.data() + b * kBlock, static_cast<uLong>(length), Z_BEST_SPEED) !=
        Z_OK)
      throw OutputError("cannot compress the data of '" + shown_ + "' (zlib)");
    packed[b].resize(size);
  });
  for (const auto& p : packed) {
    headers_.back().push_back(p.size());
    put(p.data(), p.size());
  }
  batch_used_ = 0;
}

void VtuFileWriter::close() {
  const std::size_t arrays = global_ids_ ? 7 : 6;
  if (begins_.size() != arrays) throw InternalError("'" + shown_ + "' was closed before all its arrays");
  const std::string tail = "\n</AppendedData>\n</VTKFile>\n";
  put(tail.data(), tail.size());
  out_.close();
  // The places kept: the head's offsets, each array's block sizes.
  const int fd = ::open(path_.c_str(), O_WRONLY | O_CLOEXEC);
  bool written = fd >= 0;
  const auto write_at = [&](std::uint64_t at, const void* data, std::size_t size) {
    written = written && ::lseek(fd, static_cast<off_t>(at), SEEK_SET) >= 0 && write_all(fd, data, size);
  };
  const std::string head = this->head();
  write_at(0, head.data(), head.size());
  for (std::size_t i = 0; i < arrays; ++i)
    write_at(data_start_ + begins_[i], headers_[i].data(), headers_[i].size() * sizeof(std::uint64_t));
  const int error = errno;
  if (fd >= 0) ::close(fd);
  if (!written) throw OutputError("cannot write '" + shown_ + "': " + std::strerror(error));
}

}  // namespace partet
