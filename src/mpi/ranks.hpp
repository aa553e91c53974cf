// What the parts of the MPI driver share (internal header): the job's communicator, the tags of
// its messages, rank 0's commands, how long a rank waits for another, and the bounded waits that
// end the job naming a rank that stopped answering.
#pragma once
#include <mpi.h>

#include <exception>
#include <string>

#include "common/stage_timer.hpp"
#include "mpi/transport.hpp"

namespace partet::mpi {

constexpr int kTagPiece = 1;
constexpr int kTagReply = 2;
constexpr int kTagBlock = 3;
constexpr int kTagVerdict = 5;   // rank 1's verdict on the input
constexpr int kTagFindings = 6;  // another checking rank's findings, to rank 1
constexpr int kTagBulk = 8;      // a kept bulk, back to rank 0
constexpr int kTagShare = 10;    // the shares of a seam chain of the band parts a rank keeps, to its healing rank (kTagAlive is 9)
constexpr int kTagText = 6;      // during the writes, a worker's text or answer to rank 0 (no findings then)
enum Command : int {
  kDone = 0,
  kMeshPieces = 1,
  kSendBulk = 2,
  kNumberBulks = 3,
  kLinkBulks = 4,
  kGrowBand = 5,
  kSendBand = 6,
  kCutShares = 7,
  kSendChains = 8
};

// A stopped or dead rank must end the job within a bounded time, naming it. Rank 0 allows a
// worker a piece's own wall time limit (PieceRunner::wall_limit) plus kReplyGraceSeconds to answer, and kWorkerSeconds
// for anything else (taking a message, joining an agreement); while the worker's TetGen process is at work, its
// heartbeats must not stop for kSilentSeconds (heartbeat.hpp). A worker allows rank 0, which may merge and write for
// long, kRootSeconds between messages.
constexpr double kReplyGraceSeconds = 10;
constexpr double kWorkerSeconds = 120;
constexpr double kRootSeconds = 3600;

// The communicator of the job this process runs: MPI_COMM_WORLD for the command, the caller's
// for the library (mesh_collective). One job at a time per process (TetGen keeps global state),
// so one variable is enough; UseComm sets it for as long as it lives.
MPI_Comm job_comm();
class UseComm {
 public:
  explicit UseComm(MPI_Comm comm);
  ~UseComm();
  UseComm(const UseComm&) = delete;
  UseComm& operator=(const UseComm&) = delete;

 private:
  MPI_Comm saved_;
};

// Ends the whole job now: a rank stopped answering.
[[noreturn]] void abort_job(const std::string& message);

int my_rank();

// How long this rank waits for the others in a collective step.
double collective_limit();

// Runs a collective step; a rank that does not join in time ends the job.
template <class Step>
auto bounded(Step step) {
  try {
    return step();
  } catch (const Stalled&) {
    abort_job(my_rank() == 0 ? "a worker rank did not join the agreement within " +
                                   std::to_string(static_cast<int>(kWorkerSeconds)) + " s (stopped or dead?)"
                             : "rank 0 has sent nothing for " + std::to_string(static_cast<int>(kRootSeconds)) +
                                   " s (stopped or dead?)");
  }
}

// Every rank learns whether all ranks succeeded.
bool agree(bool ok_here);

void broadcast(Command command);
Command receive_command();

// Rank 0's text to every rank.
std::string broadcast_text(const std::string& text);

// An absolute path for another rank, whose working directory may differ; an OutputError when
// this one's cannot be named.
std::string absolute_or_error(const std::string& path);

// Adds the seconds an object lives to a total.
struct AddSeconds {
  double& total;
  double start = now_seconds();
  ~AddSeconds() { total += now_seconds() - start; }
};

// What a rank that ran out of memory says (its own figures).
std::string out_of_memory_message(int rank);
// A failure's message; running out of memory as out_of_memory_message says it.
std::string error_message(std::exception_ptr failure, int rank);

}  // namespace partet::mpi
