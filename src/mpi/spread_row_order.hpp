// What rank 0 and the ranks keeping a spread mesh's bulks tell each other while rank 0 writes the
// single files (internal header; the exchange: spread_row_files.hpp): rank 0's side in
// spread_row_files.cpp, the other ranks' in stream_own_rows.cpp.
#pragma once
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "io/mesh_formats.hpp"
#include "io/row_lines.hpp"
#include "mpi/point_shares.hpp"
#include "mpi/write_messages.hpp"

namespace partet::mpi {

// Rows formatted and sent at a time: 10-16 MB of text.
inline constexpr std::size_t kRowsPerChunk = std::size_t{1} << 18;
// A claim: the piece, the fingerprints of the points and tets (2 words each), the bounds (6 doubles).
inline constexpr std::size_t kClaimWords = 11;

// Among an order's pieces: a run of rank 0's own points (the input's, most of a points section's
// rows) that the rank formats for rank 0, sent after the order: the number of its first row
// (int64), then its rows.
inline constexpr std::int32_t kGivenPoints = -1;

// A section's order to one rank: "F", the kind of rows, the number of row 0, then the pieces of
// its runs (int32 each, or kGivenPoints), in row order.
struct SectionOrder {
  RowLines lines = RowLines::tetgen_node;
  std::int64_t number_from = 0;
  std::vector<std::int32_t> pieces;
  static constexpr std::size_t kHead = 2 + sizeof(std::int64_t);

  std::string bytes() const {
    std::string order = "F";
    order += static_cast<char>(lines);
    order.append(reinterpret_cast<const char*>(&number_from), sizeof number_from);
    order.append(bytes_of(run_of(pieces)));
    return order;
  }
  // False when the bytes are no such order (an unknown kind of rows is read, and fails to format).
  bool read(const std::string& order) {
    if (order.size() < kHead || order[0] != 'F') return false;
    lines = static_cast<RowLines>(order[1]);
    std::memcpy(&number_from, order.data() + 2, sizeof number_from);
    auto values = values_of<std::int32_t>(order, kHead);
    if (values) pieces = std::move(*values);
    return values.has_value();
  }
};

// Calls f(from, count) for each chunk of `rows` rows.
template <class F>
void in_chunks(std::size_t rows, F f) {
  for (std::size_t from = 0; from < rows; from += kRowsPerChunk) f(from, std::min(kRowsPerChunk, rows - from));
}

}  // namespace partet::mpi
