// How rank 0 deals its run of the split surface's points out to the ranks to format (internal
// header, without MPI: the arithmetic alone, tested in point_shares_test).
#pragma once
#include <algorithm>
#include <cstddef>
#include <vector>

namespace partet::mpi {

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

}  // namespace partet::mpi
