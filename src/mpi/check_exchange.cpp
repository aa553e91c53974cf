#include "mpi/check_exchange.hpp"

#include <algorithm>
#include <climits>

#include "common/test_hooks.hpp"
#include "partet/errors.hpp"

namespace partet::distributed {

// How many passes `records` records of `record_bytes` each need on the rank with the most.
std::uint64_t passes_for(MPI_Comm comm, std::uint64_t records, std::size_t record_bytes) {
  static const auto budget = static_cast<std::uint64_t>(std::max(1.0, test_hooks::check_pass_bytes(kPassBytes)));
  std::uint64_t passes = std::max<std::uint64_t>(1, (records * record_bytes + budget - 1) / budget);
  reduce_in_place(&passes, 1, MPI_UINT64_T, MPI_MAX, comm);
  return std::min<std::uint64_t>(passes, 1 << 15);
}

// The rank whose run (run_of) of [0, total) holds id.
int run_owner(std::int64_t id, std::uint64_t total, int size) {
  int r = static_cast<int>((static_cast<unsigned __int128>(id) * size) / std::max<std::uint64_t>(total, 1));
  while (r + 1 < size && run_of(total, r + 1, size).first <= static_cast<std::uint64_t>(id)) ++r;
  while (r > 0 && run_of(total, r, size).first > static_cast<std::uint64_t>(id)) --r;
  return r;
}

// The lowest rank's non-empty text, on every rank ("" when every rank's is empty).
std::string first_nonempty(MPI_Comm comm, const std::string& text) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  int first = text.empty() ? INT_MAX : rank;
  reduce_in_place(&first, 1, MPI_INT, MPI_MIN, comm);
  if (first == INT_MAX) return "";
  int length = rank == first ? static_cast<int>(text.size()) : 0;
  broadcast_from(&length, 1, MPI_INT, first, comm);
  std::string out = rank == first ? text : std::string(static_cast<std::size_t>(length), ' ');
  broadcast_from(out.data(), length, MPI_CHAR, first, comm);
  return out;
}

// When any rank has an error, every rank throws InputError with the lowest such rank's message.
void throw_if_any(MPI_Comm comm, const std::string& error) {
  if (std::string first = first_nonempty(comm, error); !first.empty()) throw InputError(first);
}

}  // namespace partet::distributed
