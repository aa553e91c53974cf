#include "mpi/input_check_ranks.hpp"

#include <mpi.h>

#include <algorithm>
#include <cstring>
#include <exception>
#include <optional>
#include <string>
#include <vector>

#include "common/awake_clock.hpp"
#include "common/test_hooks.hpp"
#include "mpi/ranks.hpp"
#include "stages/input_share.hpp"
#include "stages/validate.hpp"

namespace partet::mpi {
namespace {

constexpr std::size_t kStreamPartValues = std::size_t{1} << 19;  // values per broadcast part

// How many shares the input's check has with `size` ranks: one per rank but 0, as many as a
// vertex's 16-bit share can name (ranks beyond check an empty share).
int input_shares(int size) { return std::min(size - 1, 65535); }

// Rank 0's side of one stream.
template <class T>
void broadcast_values(const std::vector<T>& values) {
  for (std::size_t first = 0; first < values.size(); first += kStreamPartValues) {
    const std::size_t n = std::min(kStreamPartValues, values.size() - first);
    bounded(
        [&] { broadcast_bytes(const_cast<T*>(values.data() + first), n * sizeof(T), 0, job_comm(), kWorkerSeconds); });
  }
}

// A checking rank's side: hands each part of `count` values to take(values, n) while the next
// part comes. After take has failed, the rest is received and dropped (rank 0 is waiting for
// every rank to take every part), and the failure is kept.
template <class T, class Take>
void receive_values(std::size_t count, std::exception_ptr& failure, const Take& take) {
  const std::size_t parts = (count + kStreamPartValues - 1) / kStreamPartValues;
  std::vector<T> buffers[2];
  MPI_Request requests[2];
  auto part_size = [&](std::size_t part) { return std::min(kStreamPartValues, count - part * kStreamPartValues); };
  auto start = [&](std::size_t part) {
    std::vector<T>& buffer = buffers[part % 2];
    buffer.resize(part_size(part));
    requests[part % 2] = start_broadcast(buffer.data(), buffer.size() * sizeof(T), 0, job_comm());
  };
  if (parts > 0) start(0);
  for (std::size_t part = 0; part < parts; ++part) {
    if (part + 1 < parts) start(part + 1);
    bounded([&] { return wait_sleeping(requests[part % 2], MPI_STATUS_IGNORE, kRootSeconds); });
    if (failure) continue;
    try {
      take(buffers[part % 2].data(), buffers[part % 2].size());
    } catch (...) {
      failure = std::current_exception();
    }
  }
}

// Receives this rank's share of the input and checks it: "F" + the findings, or "E" + an error.
std::string check_input_share(int rank, int size, std::uint64_t (&counts)[2]) {
  bounded([&] { broadcast_bytes(counts, sizeof counts, 0, job_comm(), kRootSeconds); });
  std::exception_ptr failure;
  std::optional<InputShareBuilder> builder;
  try {
    builder.emplace(rank - 1, input_shares(size), counts[0], counts[1]);
  } catch (...) {
    failure = std::current_exception();
  }
  receive_values<std::uint16_t>(counts[0], failure, [&](auto* v, std::size_t n) { builder->add_vertex_shares(v, n); });
  receive_values<Triangle>(counts[1], failure, [&](auto* v, std::size_t n) { builder->add_faces(v, n); });
  receive_values<Point3>(counts[0], failure, [&](auto* v, std::size_t n) { builder->add_points(v, n); });
  if (!failure) try {
      test_hooks::share_failure(rank);
      const InputFindings findings = check_share(builder->finish());
      return "F" + std::string(reinterpret_cast<const char*>(&findings), sizeof findings);
    } catch (...) {
      failure = std::current_exception();
    }
  return "E" + error_message(failure, rank);
}

// Rank 1: its own and the other ranks' findings, merged in rank order, judged.
std::string input_verdict(const std::string& own, int size, std::size_t faces) {
  // One deadline for all of them, so rank 0's wait for this verdict (twice the limit) ends later.
  const double limit = input_check_limit(faces), deadline = awake_seconds() + limit;
  InputFindings merged;
  for (int rank = 1; rank < size; ++rank) {
    std::string findings = own;
    if (rank > 1) try {
        findings = recv_bytes(rank, kTagFindings, job_comm(), kMaxChunk, std::max(deadline - awake_seconds(), 1e-3));
      } catch (const Stalled&) {
        return "Erank " + std::to_string(rank) + " has not reported its share of the input check within " +
               std::to_string(static_cast<int>(limit)) + " s (stopped or dead?)";
      }
    if (!findings.empty() && findings[0] == 'E') return findings;
    if (findings.size() != 1 + sizeof(InputFindings) || findings[0] != 'F')
      return "Erank " + std::to_string(rank) + " sent malformed findings of its input check";
    InputFindings share;
    std::memcpy(static_cast<void*>(&share), findings.data() + 1, sizeof share);
    merged.merge(share);
  }
  try {
    judge_input(merged);
  } catch (const InputError& e) {
    return std::string("I") + e.what();
  }
  return "";
}

}  // namespace

double input_check_limit(std::size_t faces) {
  return test_hooks::verdict_wait_seconds(kWorkerSeconds + 1e-6 * static_cast<double>(faces));
}

void send_input_for_checks(const SurfaceMesh& input, int size) {
  std::uint64_t counts[2] = {input.points.size(), input.triangles.size()};
  bounded([&] { broadcast_bytes(counts, sizeof counts, 0, job_comm(), kWorkerSeconds); });
  broadcast_values(vertex_shares(input.points, input_shares(size)));
  broadcast_values(input.triangles);
  broadcast_values(input.points);
}

void check_input_on_rank(int rank, int size, RankStats& stats) {
  const double start = now_seconds();
  std::uint64_t counts[2] = {0, 0};  // vertices, faces
  const std::string findings = check_input_share(rank, size, counts);
  stats.input_check_seconds = now_seconds() - start;
  if (rank > 1) {
    test_hooks::share_stop(rank);
    bounded([&] { return send_bytes(findings, 1, kTagFindings, job_comm(), kMaxChunk, kRootSeconds); });
    return;
  }
  const std::string verdict = input_verdict(findings, size, counts[1]);
  test_hooks::verdict_stop(1);
  bounded([&] { return send_bytes(verdict, 0, kTagVerdict, job_comm(), kMaxChunk, kRootSeconds); });
}

}  // namespace partet::mpi
