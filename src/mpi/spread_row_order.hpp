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

// How many rows of rank 0's own run of `run` points each rank formats (rank 0's share first, then
// rank 1's, ...), so that all format about as many rows of the section: kept[r] rows of it are
// rank r's anyway (its bulks; rank 0's other runs). The ranks that keep the fewest take the most.
inline std::vector<std::size_t> point_shares(std::size_t run, const std::vector<std::size_t>& kept) {
  std::size_t total = run;
  for (std::size_t rows : kept) total += rows;
  const std::size_t each = (total + kept.size() - 1) / std::max<std::size_t>(1, kept.size());
  std::vector<std::size_t> shares(kept.size(), 0);
  std::size_t left = run;
  for (std::size_t r = 1; r < kept.size(); ++r) {
    shares[r] = std::min(left, each > kept[r] ? each - kept[r] : 0);
    left -= shares[r];
  }
  if (!shares.empty()) shares[0] = left;
  return shares;
}

// Calls f(from, count) for each chunk of `rows` rows.
template <class F>
void in_chunks(std::size_t rows, F f) {
  for (std::size_t from = 0; from < rows; from += kRowsPerChunk) f(from, std::min(kRowsPerChunk, rows - from));
}

}  // namespace partet::mpi
