// The check on several ranks (distributed_check.hpp), internal: the part of the mesh each rank
// holds, records moved between ranks, the passes they are gathered in, and errors every rank
// agrees on.
#pragma once
#include <mpi.h>

#include <array>
#include <cstdint>
#include <new>
#include <string>
#include <vector>

#include "io/xdmf.hpp"
#include "mpi/collective_watch.hpp"

namespace partet::distributed {

using Id = std::int64_t;

// ---------------------------------------------------------------------------------------------
// Moving records between ranks

template <class T>
MPI_Datatype record_type() {
  static MPI_Datatype type = [] {
    MPI_Datatype t;
    MPI_Type_contiguous(static_cast<int>(sizeof(T)), MPI_BYTE, &t);
    MPI_Type_commit(&t);
    return t;
  }();
  return type;
}

// The check's collective calls. Each ends a step of the watch the check runs under
// (collective_watch.hpp): without it a rank that stops mid-check would hold the others in the
// next call for ever.
inline void reduce_in_place(void* values, int count, MPI_Datatype type, MPI_Op op, MPI_Comm comm) {
  MPI_Allreduce(MPI_IN_PLACE, values, count, type, op, comm);
  mpi::collective_step_ended();
}

inline void broadcast_from(void* values, int count, MPI_Datatype type, int root, MPI_Comm comm) {
  MPI_Bcast(values, count, type, root, comm);
  mpi::collective_step_ended();
}

// Sends outgoing[r] to rank r (each bucket freed as it is packed); returns what every rank sent
// here, in rank order, and how many came from each (from_counts, if given).
template <class T>
std::vector<T> all_to_all(MPI_Comm comm, std::vector<std::vector<T>>&& outgoing,
                          std::vector<int>* from_counts = nullptr) {
  const int size = static_cast<int>(outgoing.size());
  std::vector<int> send_counts(size), receive_counts(size), send_at(size, 0), receive_at(size, 0);
  std::size_t sending = 0;
  for (int r = 0; r < size; ++r) send_counts[r] = static_cast<int>(outgoing[r].size()), sending += outgoing[r].size();
  MPI_Alltoall(send_counts.data(), 1, MPI_INT, receive_counts.data(), 1, MPI_INT, comm);
  mpi::collective_step_ended();
  std::vector<T> flat;
  flat.reserve(sending);
  for (int r = 0; r < size; ++r) {
    send_at[r] = static_cast<int>(flat.size());
    flat.insert(flat.end(), outgoing[r].begin(), outgoing[r].end());
    std::vector<T>().swap(outgoing[r]);
  }
  std::size_t total = 0;
  for (int r = 0; r < size; ++r) receive_at[r] = static_cast<int>(total), total += receive_counts[r];
  std::vector<T> incoming(total);
  MPI_Alltoallv(flat.data(), send_counts.data(), send_at.data(), record_type<T>(), incoming.data(),
                receive_counts.data(), receive_at.data(), record_type<T>(), comm);
  mpi::collective_step_ended();
  if (from_counts) *from_counts = receive_counts;
  return incoming;
}

inline std::uint64_t mix(std::uint64_t x) {  // splitmix64's finalizer
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// The checks that gather records by key run in passes, each over the keys whose hash falls in one
// bucket, so that a rank holds one pass's records at a time (about kPassBytes of its own, and
// about as much received) instead of all of them: at 33M tets on 2 ranks a rank's face records
// alone took 2.1 GB, and rank 0's records of the input's 22M triangles 1.8 GB.
inline constexpr std::uint64_t kPassBytes = std::uint64_t(256) << 20;

// How many passes `records` records of `record_bytes` each need on the rank with the most.
std::uint64_t passes_for(MPI_Comm comm, std::uint64_t records, std::size_t record_bytes);

// Where a key's records meet: the rank and the pass its hash picks.
struct KeyPlace {
  int rank;
  std::uint64_t pass;
};

template <std::size_t N>
KeyPlace place_of_key(const std::array<std::uint64_t, N>& key, int size, std::uint64_t passes) {
  std::uint64_t h = 0;
  for (std::uint64_t k : key) h = mix(h ^ k);
  const auto ranks = static_cast<std::uint64_t>(size);
  return {static_cast<int>(h % ranks), (h / ranks) % passes};
}

// ---------------------------------------------------------------------------------------------
// The part of the mesh this rank holds

// The rank whose run (run_of) of [0, total) holds id.
int run_owner(std::int64_t id, std::uint64_t total, int size);

struct Part {
  MPI_Comm comm;
  int rank = 0, size = 1;
  MeshTotals totals;
  MeshBlock block;
  // This rank's points are [first_point, first_point + block.points.size()).
  std::uint64_t run_start(std::uint64_t total, int r) const { return run_of(total, r, size).first; }
  int point_owner(Id id) const { return run_owner(id, totals.points, size); }
  bool valid(Id id) const { return id >= 0 && static_cast<std::uint64_t>(id) < totals.points; }
};

// ---------------------------------------------------------------------------------------------
// Errors every rank agrees on

// The lowest rank's non-empty text, on every rank ("" when every rank's is empty).
std::string first_nonempty(MPI_Comm comm, const std::string& text);

// When any rank has an error, every rank throws InputError with the lowest such rank's message.
void throw_if_any(MPI_Comm comm, const std::string& error);

// Runs read, turning what it throws into this rank's error (an allocation failure too: the
// other ranks must not wait for a rank that has given up).
template <class Read>
std::string error_of(const std::string& path, const Read& read) {
  try {
    read();
  } catch (const std::bad_alloc&) {
    return "out of memory reading '" + path + "': run the check on more ranks";
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace partet::distributed
