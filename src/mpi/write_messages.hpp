// The messages of the writes from a spread mesh (internal header): rank 0 sends its orders and
// parts on kTagBlock, the others answer on kTagText; both wait within the driver's bounds.
#pragma once
#include <cstring>
#include <exception>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/buffered_file.hpp"
#include "mpi/ranks.hpp"
#include "partet/errors.hpp"

namespace partet::mpi {

inline void send_to(int rank, std::string_view bytes, double seconds) {
  bounded([&] { return send_bytes(bytes, rank, rank == 0 ? kTagText : kTagBlock, job_comm(), kMaxChunk, seconds); });
}

inline std::string receive_from(int rank, double seconds) {
  return bounded([&] { return recv_bytes(rank, rank == 0 ? kTagBlock : kTagText, job_comm(), kMaxChunk, seconds); });
}

// The values in `bytes` after its first `skip` bytes; nothing when they do not divide evenly.
// A copy: the received strings do not outlive the call.
template <class T>
std::optional<std::vector<T>> values_of(const std::string& bytes, std::size_t skip = 0) {
  if (bytes.size() < skip || (bytes.size() - skip) % sizeof(T) != 0) return std::nullopt;
  std::vector<T> values((bytes.size() - skip) / sizeof(T));
  if (!values.empty()) std::memcpy(values.data(), bytes.data() + skip, bytes.size() - skip);
  return values;
}

// Takes a rank's chunks of text ("T" + text, or "E" + why it could not) until its empty one,
// writing them into `out` (a BufferedFile or a ByteSink) unless a failure came first (then kept in
// `failure`): after a failure the rank is still heard out, so it is not left waiting.
template <class Out>
void take_text_chunks(Out& out, int rank, std::exception_ptr& failure) {
  for (std::string chunk = receive_from(rank, kWorkerSeconds); !chunk.empty();
       chunk = receive_from(rank, kWorkerSeconds)) {
    if (failure) continue;
    if (chunk[0] == 'E') {
      failure = std::make_exception_ptr(OutputError(chunk.substr(1)));
      continue;
    }
    try {
      out.bytes(chunk.data() + 1, chunk.size() - 1);
    } catch (...) {
      failure = std::current_exception();
    }
  }
}

}  // namespace partet::mpi
