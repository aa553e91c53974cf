#include "mpi/ranks.hpp"

#include <cstdlib>
#include <new>

#include "common/log.hpp"
#include "common/memory.hpp"
#include "common/paths.hpp"
#include "partet/errors.hpp"

namespace partet::mpi {

namespace {
MPI_Comm current_comm = MPI_COMM_WORLD;
}  // namespace

MPI_Comm job_comm() { return current_comm; }
UseComm::UseComm(MPI_Comm comm) : saved_(current_comm) { current_comm = comm; }
UseComm::~UseComm() { current_comm = saved_; }

[[noreturn]] void abort_job(const std::string& message) {
  log::error(message + "; ending the job");
  MPI_Abort(job_comm(), 1);
  std::abort();  // MPI_Abort does not return
}

int my_rank() {
  int rank = 0;
  MPI_Comm_rank(job_comm(), &rank);
  return rank;
}

double collective_limit() { return my_rank() == 0 ? kWorkerSeconds : kRootSeconds; }

bool agree(bool ok_here) {
  return bounded([&] { return all_true(ok_here, job_comm(), collective_limit()); });
}

void broadcast(Command command) {
  bounded([&] { return broadcast_int(command, 0, job_comm(), collective_limit()); });
}

Command receive_command() {
  return static_cast<Command>(bounded([&] { return broadcast_int(kDone, 0, job_comm(), collective_limit()); }));
}

std::string absolute_or_error(const std::string& path) {
  std::string absolute = absolute_path(path);
  if (absolute.empty() || absolute[0] != '/') throw OutputError("cannot find the working directory");
  return absolute;
}

std::string broadcast_text(const std::string& text) {
  const int size =
      bounded([&] { return broadcast_int(static_cast<int>(text.size()), 0, job_comm(), collective_limit()); });
  std::string received = text;
  received.resize(static_cast<std::size_t>(size));
  // (Bounded too: past MPI's eager limit rank 0 waits for every rank to take the text.)
  bounded([&] {
    broadcast_bytes(received.data(), received.size(), 0, job_comm(), collective_limit());
    return 0;
  });
  return received;
}

std::string out_of_memory_message(int rank) {
  const std::string name = "rank " + std::to_string(rank);
  return name + " ran out of memory (at " + std::to_string(static_cast<long>(own_peak_rss_mb())) +
         " MB; the machine has " + std::to_string(static_cast<long>(available_memory_mb())) +
         " MB available now): use a machine with more memory for " + name;
}

std::string error_message(std::exception_ptr failure, int rank) {
  try {
    std::rethrow_exception(failure);
  } catch (const std::bad_alloc&) {
    return out_of_memory_message(rank);
  } catch (const std::exception& e) {
    return e.what();
  }
}

}  // namespace partet::mpi
