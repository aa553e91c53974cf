// One .vtu file as partet writes it (internal header): an UnstructuredGrid of tets, its arrays
// appended raw and zlib-compressed in VTK's blocks, written array by array as their bytes come,
// so that no copy of the whole data is held. The appended arrays, in order: Points (Float64 x 3),
// connectivity, offsets (Int64), types (UInt8), the cell data piece and region (Int32), and, in a
// .pvtu set's piece file, the point data GlobalPointIds (Int64).
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "io/buffered_file.hpp"
#include "io/row_lines.hpp"

namespace partet {

enum class VtuArray { points, connectivity, offsets, types, piece, region, global_ids };

class VtuFileWriter : private ByteSink {
 public:
  // Into `path`, which must exist (an OutputSet's temporary, maybe made on another rank); errors
  // name `shown`.
  VtuFileWriter(const std::string& path, const std::string& shown, std::uint64_t points, std::uint64_t cells,
                bool global_ids);
  VtuFileWriter(const VtuFileWriter&) = delete;
  VtuFileWriter& operator=(const VtuFileWriter&) = delete;
  ~VtuFileWriter() override;

  // The next array, in order: `fill` gives all its raw bytes (in pieces of any size). Throws
  // OutputError when they are not as many as the counts make them.
  void array(VtuArray which, const std::function<void(ByteSink& out)>& fill);
  // The offsets and types arrays, made from the count of cells.
  void cell_layout();
  // Writes the rest, then the offsets and block sizes into the places kept for them.
  void close();

 private:
  void bytes(const void* data, std::size_t size) override;
  void compress_batch();
  void put(const void* data, std::size_t size);
  std::string head() const;

  std::string path_, shown_;
  std::uint64_t points_, cells_;
  bool global_ids_;
  BufferedFile out_;
  std::uint64_t position_ = 0;  // bytes written into out_
  // The arrays written so far: where each begins (from the appended data's start) and its header
  // (blocks, block size, last block's size, each block's compressed size).
  std::vector<std::uint64_t> begins_;
  std::vector<std::vector<std::uint64_t>> headers_;
  std::uint64_t data_start_ = 0;  // the file's byte of the appended data's first
  // The current array: its expected and received raw bytes, and the raw bytes not yet compressed.
  std::uint64_t expected_ = 0, received_ = 0;
  std::vector<unsigned char> batch_;
  std::size_t batch_used_ = 0;
};

}  // namespace partet
