// The distributed job, its steps in order (run_mesh_job): rank 0 prepares, the ranks check the
// input and mesh (root_scheduler.hpp on rank 0, worker.hpp elsewhere), every rank takes part in
// the writes (rank_writes.hpp), and all agree before rank 0 publishes.
#include "mpi/driver.hpp"

#include <mpi.h>
#include <sched.h>

#include <cstring>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/log.hpp"
#include "common/memory.hpp"
#include "common/parallel.hpp"
#include "common/test_hooks.hpp"
#include "job/root_run.hpp"
#include "mpi/input_check_ranks.hpp"
#include "mpi/rank_writes.hpp"
#include "mpi/ranks.hpp"
#include "mpi/root_scheduler.hpp"
#include "mpi/set_check.hpp"
#include "mpi/worker.hpp"
#include "partet/errors.hpp"
#include "runner/interrupts.hpp"

namespace partet::mpi {
namespace {

// The CPUs of the ranks on rank 0's node (same processor name), from their affinity masks: rank 0
// borrows them while those ranks wait for its writes (CpuLoan). Empty on the other ranks.
cpu_set_t cpus_of_rank0_node(int rank, int size) {
  struct Where {
    char host[MPI_MAX_PROCESSOR_NAME];
    cpu_set_t cpus;
  };
  Where mine{};
  int length = 0;
  MPI_Get_processor_name(mine.host, &length);
  if (::sched_getaffinity(0, sizeof mine.cpus, &mine.cpus) != 0) CPU_ZERO(&mine.cpus);
  std::vector<Where> all(rank == 0 ? static_cast<std::size_t>(size) : 0);
  bounded([&] { gather_bytes(&mine, sizeof mine, all.data(), 0, job_comm(), collective_limit()); });
  cpu_set_t cpus;
  CPU_ZERO(&cpus);
  for (const Where& where : all)
    if (std::strncmp(where.host, all[0].host, sizeof where.host) == 0) CPU_OR(&cpus, &cpus, &where.cpus);
  return cpus;
}

// What one rank knows about the job as it runs (rank 0's story is in RootRun).
struct RankState {
  int rank = 0, size = 1;
  double start = now_seconds();
  RankStats stats;
  JobStatus status;
  std::map<int, PieceRecord> records;  // piece index -> where and how long it was meshed (rank 0 only)
};

// An error as it crosses ranks: its type and message.
struct ErrorText {
  int type = 0;  // 0 Error, 1 InputError, 2 OptionError, 3 MeshingError, 4 InputMeshingError
  std::string message;
};

ErrorText error_text(std::exception_ptr failure) {
  try {
    std::rethrow_exception(failure);
  } catch (const InputMeshingError& e) {
    return {4, e.what()};
  } catch (const MeshingError& e) {
    return {3, e.what()};
  } catch (const OptionError& e) {
    return {2, e.what()};
  } catch (const InputError& e) {
    return {1, e.what()};
  } catch (const std::exception& e) {
    return {0, e.what()};
  } catch (...) {
    return {0, "unknown error"};
  }
}

// Rank 0's error to every rank (rank 0 is alive: it has just joined an agreement).
void broadcast_error(ErrorText& error, MPI_Comm comm) {
  long long header[2] = {error.type, static_cast<long long>(error.message.size())};
  MPI_Bcast(header, 2, MPI_LONG_LONG, 0, comm);
  error.type = static_cast<int>(header[0]);
  error.message.resize(static_cast<std::size_t>(header[1]));
  MPI_Bcast(error.message.data(), static_cast<int>(header[1]), MPI_CHAR, 0, comm);
}

[[noreturn]] void throw_error(const ErrorText& error) {
  switch (error.type) {
    case 4:
      throw InputMeshingError(Failure{FailureKind::other, -1, {}, error.message});
    case 3:
      throw MeshingError(Failure{FailureKind::other, -1, {}, error.message});
    case 2:
      throw OptionError(error.message);
    case 1:
      throw InputError(error.message);
    default:
      throw Error(error.message);
  }
}

// What an interrupt says on rank 0, before and after the new files are in place.
std::string interrupted_before(const MeshJob& job) {
  const std::string& kept = job.options.run.checkpoint;
  return "interrupted (%s): no output written; the files at " + job.output_prefix + " are as they were" +
         (kept.empty() ? " (with --checkpoint DIR a rerun would take the pieces meshed so far)"
                       : "; the pieces meshed so far are kept in " + kept + ": the same command takes them");
}
std::string interrupted_after(const MeshJob& job) {
  return "%s after the output was published: the new files at " + job.output_prefix + " are complete";
}

// Runs a rank-0 step, turning its exception into the job's error.
template <class Step>
void on_root(RankState& state, Step step) {
  try {
    step();
  } catch (const MeshingError& e) {
    state.status.error = e.what();
    const auto* input_trouble = dynamic_cast<const InputMeshingError*>(&e);
    state.status.meshing_failed = input_trouble == nullptr;
    state.status.split_faces_may_help = input_trouble && input_trouble->split_faces_may_help;
    state.status.out_of_time = e.failure.kind == FailureKind::timed_out;
  } catch (const OptionError& e) {
    state.status.error = e.what();
    state.status.usage_error = true;
  } catch (const std::bad_alloc&) {
    state.status.error = out_of_memory_message(0);
  } catch (const std::exception& e) {
    state.status.error = e.what();
  }
}

// Every rank's figures, gathered on rank 0 (empty elsewhere).
std::vector<RankStats> gather_rank_stats(RankState& state) {
  state.stats.peak_rss_mb = own_peak_rss_mb();
  state.stats.tetgen_child_peak_rss_mb = children_peak_rss_mb();
  std::vector<RankStats> all(state.rank == 0 ? state.size : 0);
  bounded([&] {
    gather_bytes(&state.stats, static_cast<int>(sizeof(RankStats)), all.data(), 0, job_comm(), collective_limit());
    return 0;
  });
  return all;
}

// Only when every rank succeeded does rank 0 publish the files (all at once); then every rank
// learns whether that worked too.
void agree_and_publish(RankState& state, std::optional<RootRun>& root) {
  test_hooks::worker_death(state.rank);
  const std::vector<RankStats> ranks = gather_rank_stats(state);
  bool ok = agree(state.status.error.empty());
  if (ok && root) {
    on_root(state, [&] { root->publish(ranks, state.records, now_seconds() - state.start); });
    state.status.figures = root->figures();
  }
  state.status.ranks = state.size;
  if (ok) ok = agree(state.status.error.empty());
  if (!ok) state.status.exit_code = 1;
}

}  // namespace

std::string library_version() {
  char text[MPI_MAX_LIBRARY_VERSION_STRING];
  int length = 0;
  MPI_Get_library_version(text, &length);
  const std::string version(text, static_cast<std::size_t>(length));
  return version.substr(0, version.find(','));
}

MeshResult mesh_collective(const SurfaceMesh& input, const MeshOptions& options, MPI_Comm comm, StageTimes* times,
                           std::exception_ptr failed_before) {
  const UseComm use(comm);
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  log::set_rank(rank);
  MeshJob job;
  job.options = options;
  RankStats stats;
  MeshResult result;
  std::exception_ptr failure = rank == 0 ? failed_before : nullptr;
  if (rank == 0) {
    if (!failure) try {
        std::map<int, PieceRecord> records;
        const auto scheduler = root_scheduler(job, size, stats, records, now_seconds());
        result = mesh_with_retries(input, options, *scheduler, times);
      } catch (...) {
        failure = std::current_exception();
      }
    broadcast(kDone);
  } else {
    worker_loop(job, rank, stats);
  }
  if (agree(!failure)) return result;
  // Every rank throws: rank 0 its own error, the others one of the same type with its message.
  ErrorText error = failure ? error_text(failure) : ErrorText{};
  broadcast_error(error, comm);
  if (failure) std::rethrow_exception(failure);
  throw_error(error);
}

JobStatus run_mesh_job(const MeshJob& job) {
  RankState state;
  MPI_Comm_rank(job_comm(), &state.rank);
  MPI_Comm_size(job_comm(), &state.size);
  log::set_rank(state.rank);
  std::optional<RootRun> root;  // rank 0's story
  if (state.rank == 0) root.emplace(job);
  // 1-2. Rank 0 checks where the output goes, then reads and validates the input. An interrupted
  // rank removes its temporary files; rank 0 says which files are in place.
  const InputChecks checks = state.size > 1 ? InputChecks::elsewhere : InputChecks::here;
  const cpu_set_t node_cpus = cpus_of_rank0_node(state.rank, state.size);
  if (root) {
    interrupts::set_messages(interrupted_before(job), interrupted_after(job));
    on_root(state, [&] {
      const CpuLoan loan(node_cpus);  // the ranks on this node wait for the input meanwhile
      root->prepare(checks);
    });
  }
  // Only rank 0 can have failed so far: its exit code goes to every rank (2: a usage error).
  const int start_code = state.status.error.empty() ? 0 : state.status.usage_error ? 2 : 1;
  state.status.exit_code = bounded([&] { return broadcast_int(start_code, 0, job_comm(), collective_limit()); });
  if (state.status.exit_code != 0) return state.status;
  // 2b. The other ranks check the input while rank 0 partitions it (the verdict comes before any piece).
  if (checks == InputChecks::elsewhere) {
    if (root)
      send_input_for_checks(root->input(), state.size);
    else
      check_input_on_rank(state.rank, state.size, state.stats);
  }
  // 3-8. Rank 0 partitions, closes, merges and heals; every rank meshes pieces and regions.
  if (root) {
    on_root(state, [&] {
      std::optional<std::size_t> verdict_faces;
      if (checks == InputChecks::elsewhere) verdict_faces = root->input().triangles.size();
      const auto scheduler = root_scheduler(job, state.size, state.stats, state.records, state.start, verdict_faces);
      root->mesh(*scheduler);
    });
    broadcast(kDone);
    // 9. Back to the input's scale, checked and written under temporary names.
    if (state.status.error.empty())
      on_root(state, [&] {
        const AddSeconds timer{state.stats.write_seconds};
        const CpuLoan loan(node_cpus);  // the ranks on this node only format and wait meanwhile
        root->check_and_write(
            rank_writers(state.size, state.stats, root->result().spread.get(), root->scale_exponent()),
            check_on_every_rank);
      });
    end_writes();
  } else {
    Worker worker(job, state.rank, state.stats);  // keeps its bulks until the writes (spread mesh)
    worker.mesh_rounds();
    join_writes(
        state.status, state.stats, [&worker] { return worker.take_kept_bulks(); },
        [&worker] { return worker.take_kept_chains(); });
  }
  // 10. Every rank agrees; rank 0 publishes and reports.
  agree_and_publish(state, root);
  return state.status;
}

}  // namespace partet::mpi
