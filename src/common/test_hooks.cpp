#include "common/test_hooks.hpp"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <string>
#include <thread>

#include "partet/errors.hpp"

namespace partet::test_hooks {
namespace {

const char* value(const char* name) { return std::getenv(name); }

// Whether PARTET_INJECT_FAILURE names this failure.
bool injected(const char* failure) {
  const char* spec = value("PARTET_INJECT_FAILURE");
  return spec && std::string(spec) == failure;
}

// A number of seconds from the environment, else fallback.
double seconds_or(const char* name, double fallback) {
  const char* s = value(name);
  return s ? std::atof(s) : fallback;
}

void sleep_ms(const char* name) {
  if (const char* ms = value(name)) std::this_thread::sleep_for(std::chrono::milliseconds(std::atoi(ms)));
}

}  // namespace

void piece_failure(int piece, std::size_t triangles, int rank) {
  const char* most_faces = value("PARTET_TEST_PIECE_MEMORY_FACES");
  if (most_faces && triangles > static_cast<std::size_t>(std::atoll(most_faces))) ::raise(SIGKILL);
  const char* spec = value("PARTET_INJECT_FAILURE");
  if (!spec) return;
  const std::string s(spec);
  const auto colon = s.find(':');
  const std::string number = s.substr(0, colon == std::string::npos ? 0 : colon);  // not "worker:..."
  if (number.empty() || number.find_first_not_of("0123456789") != std::string::npos || std::stoi(number) != piece)
    return;
  if (s.substr(colon + 1) == "stall") {
    // Wall time passes, no CPU time: what a process starved of its core sees.
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds_or("PARTET_TEST_STALL_S", 5)));
    return;
  }
  if (s.substr(colon + 1) == "abort") {
    std::fprintf(stderr, "partet: rank %d: piece %d: injected abort\n", rank, piece);
    std::fflush(stderr);
    std::abort();
  }
  throw MeshingError(FailureKind::injected, piece, "injected failure (PARTET_INJECT_FAILURE)");
}

void worker_cap_failure(int plane) {
  if (injected("worker:cap-error"))
    throw PartitionError(FailureKind::other, -1,
                         "cut plane " + std::to_string(plane) + ": injected cap failure (PARTET_INJECT_FAILURE)");
}

bool every_cut_fails(std::size_t pieces) { return pieces > 1 && injected("cuts"); }

bool input_needs_surface_points() { return injected("surface"); }

void worker_stop(int rank) {
  if (rank == 1 && injected("worker:stop-when-idle")) ::raise(SIGSTOP);
}

void cap_stop(int rank) {
  if (rank == 1 && injected("worker:stop-on-cap")) ::raise(SIGSTOP);
}

void chain_stop(int rank) {
  if (rank == 1 && injected("worker:stop-on-chain")) ::raise(SIGSTOP);
}

void kept_bulk_stop(int rank, const char* command) {
  if (rank == 1 && injected((std::string("worker:stop-on-") + command).c_str())) ::raise(SIGSTOP);
}

void kept_shares_failure(int rank) {
  if (rank == 1 && injected("worker:shares-error")) throw InternalError("injected failure to cut the shares");
}

double kept_bulk_seconds(double fallback) { return seconds_or("PARTET_TEST_WORKER_S", fallback); }

double collective_step_seconds(double fallback) { return seconds_or("PARTET_TEST_COLLECTIVE_S", fallback); }

void verdict_stop(int rank) {
  if (rank == 1 && injected("worker:stop-before-verdict")) ::raise(SIGSTOP);
}

void share_failure(int rank) {
  if (rank == 2 && injected("worker:share-out-of-memory")) throw std::bad_alloc();
}

void meshing_stop(int rank) {
  static bool stopped = false;  // once: resumed, it goes on
  if (rank == 1 && !stopped && injected("worker:stop-while-meshing")) {
    stopped = true;
    ::raise(SIGSTOP);
  }
}

double silence_seconds(double fallback) { return seconds_or("PARTET_TEST_SILENCE_S", fallback); }

void share_stop(int rank) {
  if (rank == 2 && injected("worker:stop-before-findings")) ::raise(SIGSTOP);
}

void check_failure(int rank) {
  if (rank == 1 && injected("check:out-of-memory")) throw std::bad_alloc();
}

void check_stop(int rank) {
  if (rank == 1 && injected("check:stop")) ::raise(SIGSTOP);
}

void check_start_stop(int rank) {
  if (rank == 1 && injected("check:stop-at-start")) ::raise(SIGSTOP);
}

bool check_finds_inverted_tet(int rank) { return rank == 1 && injected("check:inverted-tet"); }

double check_pass_bytes(double fallback) { return seconds_or("PARTET_TEST_CHECK_PASS_BYTES", fallback); }

double verdict_wait_seconds(double fallback) { return seconds_or("PARTET_TEST_VERDICT_WAIT_S", fallback); }

void worker_death(int rank) {
  if (rank == 1 && injected("worker:abort-before-agreement")) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    std::abort();
  }
}

void write_out_of_memory(int rank) {
  if (rank == 1 && injected("worker:write-out-of-memory")) throw std::bad_alloc();
}

bool block_lost(int rank) { return rank == 1 && injected("worker:lose-block"); }

bool points_lost(int rank) { return rank == 1 && injected("worker:lose-points"); }

bool output_unseen(int rank) { return rank == 1 && injected("worker:output-unseen"); }

int publish_failure() {
  const char* spec = value("PARTET_INJECT_PUBLISH_FAILURE");
  return spec ? std::atoi(spec) : 0;
}

void publish_step(int step) {
  sleep_ms("PARTET_TEST_PUBLISH_DELAY_MS");
  if (const char* spec = value("PARTET_TEST_PUBLISH_SIGNAL")) {
    int at = 0, signal_number = 0;
    if (std::sscanf(spec, "%d:%d", &at, &signal_number) == 2 && at == step) {
      ::kill(::getpid(), signal_number);
      ::usleep(100000);  // the interrupt thread acts meanwhile, as on a busy machine, unless it must wait
    }
  }
}

void before_publish() { sleep_ms("PARTET_TEST_PAUSE_BEFORE_PUBLISH_MS"); }

double publish_wait_seconds(double fallback) { return seconds_or("PARTET_TEST_PUBLISH_WAIT_S", fallback); }

void buffer_handed() { sleep_ms("PARTET_TEST_WRITE_DELAY_MS"); }

int quota_refusal() {
  static const int refusals = static_cast<int>(seconds_or("PARTET_TEST_QUOTA_WRITES", 0));
  static std::atomic<int> refused{0};
  return refusals > 0 && refused.fetch_add(1) < refusals ? EDQUOT : 0;
}

bool assemble_always() { return value("PARTET_TEST_ASSEMBLE") != nullptr; }

double available_mb_for_check(double measured) { return seconds_or("PARTET_TEST_AVAILABLE_MB", measured); }

double free_disk_mb(double measured) {
  const char* list = value("PARTET_TEST_FREE_DISK_MB");
  if (!list) return measured;
  static int looks = 0;  // (rank 0's main thread alone looks)
  std::string values = list, item;
  for (int i = 0; i <= looks; ++i) {
    const std::size_t comma = values.find(',');
    item = values.substr(0, comma);
    if (comma == std::string::npos) break;
    values.erase(0, comma + 1);
  }
  ++looks;
  return std::atof(item.c_str());
}

double disk_capacity_mb(double measured) { return seconds_or("PARTET_TEST_DISK_CAPACITY_MB", measured); }

double disk_poll_seconds(double fallback) {
  return seconds_or("PARTET_TEST_DISK_POLL_S", value("PARTET_TEST_FREE_DISK_MB") ? 0.1 : fallback);
}

bool nameless_files_refused() { return value("PARTET_TEST_NO_NAMELESS_FILES") != nullptr; }

void interrupt_cleanup() {
  // (The signal thread knows no MPI rank: the launcher's variable tells it.)
  const char* spec = value("PARTET_TEST_INTERRUPT_DELAY");
  const char* rank = value("OMPI_COMM_WORLD_RANK");
  int on_rank = -1, ms = 0;
  if (spec && std::sscanf(spec, "%d:%d", &on_rank, &ms) == 2 && on_rank == (rank ? std::atoi(rank) : 0))
    std::this_thread::sleep_for(std::chrono::milliseconds(ms));
}

}  // namespace partet::test_hooks
