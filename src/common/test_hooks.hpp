// Fault injection for the tests, all in one place: each hook reads one environment variable and
// does nothing when it is unset (internal header). The tests that use them: tests/mpi/failure.sh,
// tests/cli/hard_parts.sh, tests/mpi/spread_output.sh, tests/mpi/stopped_rank.sh (its verdict, cap and silent modes
// too), tests/cli/outputs.sh, tests/cli/publish.sh, tests/mpi/xdmf_trouble.sh, tests/mpi/starved_piece.sh,
// tests/mpi/check_tetgen_ranks.sh (also check_failure, check_stop and check_start_stop), tests/mpi/cap_failure.sh,
// tests/mpi/shares_failure.sh, tests/mpi/spread_check.sh (the check hooks too).
#pragma once
#include <cstddef>

namespace partet::test_hooks {

// PARTET_INJECT_FAILURE="P:error" makes piece P fail with an error, "P:abort" makes the process
// meshing piece P abort (on a worker that kills the rank, as a real crash would), "P:stall"
// makes it sleep PARTET_TEST_STALL_S seconds (5 s) first, as a process starved of its core.
// PARTET_TEST_PIECE_MEMORY_FACES=N: the process meshing a piece of more than N triangles kills
// itself with SIGKILL, as the out-of-memory killer kills one that needs more than the node has.
void piece_failure(int piece, std::size_t triangles, int rank);
// PARTET_INJECT_FAILURE="cuts": every partition into more than one piece fails, as if TetGen could
// not recover a cap (so only the one-piece fallback can mesh the input). True then.
bool every_cut_fails(std::size_t pieces);
// PARTET_INJECT_FAILURE="surface": every partition fails on an input triangle, as TetGen does on an
// input it cannot mesh without points on its surface (whatever the cuts). True then.
bool input_needs_surface_points();
// PARTET_INJECT_FAILURE="worker:cap-error": every cap a rank other than 0 triangulates fails (a
// PartitionError, as when the loops on its plane cross), so rank 0 must take that failure as its own.
void worker_cap_failure(int plane);
// PARTET_INJECT_FAILURE="worker:stop-on-cap": rank 1 stops itself (SIGSTOP) when it is given a
// cap to triangulate, so rank 0 waits for a cap that never comes.
void cap_stop(int rank);
// PARTET_INJECT_FAILURE="worker:stop-on-chain": rank 1 stops itself (SIGSTOP) once it has told
// rank 0 that it heals the chain of the seams it was given, so it falls silent mid-chain.
void chain_stop(int rank);
// PARTET_INJECT_FAILURE="worker:stop-on-COMMAND": rank 1 stops itself (SIGSTOP) when rank 0 asks
// it for something of the bulks it keeps, so rank 0 waits for an answer that never comes. COMMAND:
// "grow" (a band to grow with its bulk), "take" (a bulk to send back), "links" (its bulks' links),
// "shares" (the seam chains' shares of its band parts), "write" (it joins the XDMF set's parallel
// HDF5 write, so the other ranks wait inside it).
void kept_bulk_stop(int rank, const char* command);
// PARTET_TEST_COLLECTIVE_S=S: how long a rank waits in one step of a parallel HDF5 write or of a
// check on several ranks for the other ranks before it ends the job (collective_watch.hpp; else
// fallback).
double collective_step_seconds(double fallback);
// PARTET_INJECT_FAILURE="worker:shares-error": rank 1 cannot cut the seam chains' shares of the
// band parts it keeps (an InternalError), so every chain it has a share of fails.
void kept_shares_failure(int rank);
// PARTET_TEST_WORKER_S=S: how long rank 0 waits for a rank to answer a command on the bulks it
// keeps (send one, its links, grow a band; else fallback).
double kept_bulk_seconds(double fallback);
// PARTET_INJECT_FAILURE="worker:stop-when-idle": rank 1 stops itself (SIGSTOP) after its first
// reply, so rank 0's next piece finds no one to take it.
void worker_stop(int rank);
// PARTET_INJECT_FAILURE="worker:stop-while-meshing": rank 1 stops itself (SIGSTOP) once it has
// told rank 0 that its first piece's TetGen process is at work, so it falls silent mid-piece.
void meshing_stop(int rank);
// PARTET_TEST_SILENCE_S=S: how long rank 0 lets a rank whose TetGen process is at work be silent
// before it takes the rank for stopped or lost (else fallback).
double silence_seconds(double fallback);
// PARTET_INJECT_FAILURE="worker:stop-before-verdict": rank 1 stops itself (SIGSTOP) once it has
// checked the input, before it reports the verdict rank 0 waits for.
void verdict_stop(int rank);
// PARTET_INJECT_FAILURE="worker:share-out-of-memory": rank 2 runs out of memory checking its
// share of the input (std::bad_alloc).
void share_failure(int rank);
// PARTET_INJECT_FAILURE="worker:stop-before-findings": rank 2 stops itself (SIGSTOP) once it has
// checked its share of the input, before it sends its findings to rank 1.
void share_stop(int rank);
// PARTET_INJECT_FAILURE="check:out-of-memory": in a check on several ranks, rank 1 runs out of
// memory (std::bad_alloc) once the files are read, while the other ranks go on into the checks.
void check_failure(int rank);
// PARTET_INJECT_FAILURE="check:stop": in a check on several ranks, rank 1 stops itself (SIGSTOP)
// once the files are read, so the other ranks wait for it in the check's next exchange.
void check_stop(int rank);
// PARTET_INJECT_FAILURE="check:stop-at-start": rank 1 stops itself (SIGSTOP) as a check on
// several ranks starts (`partet check` under mpirun, `mesh --check` reading its parts back),
// before the ranks first meet.
void check_start_stop(int rank);
// check:inverted-tet: rank 1 of a check on several ranks counts one inverted tet more (a check
// that fails, for `mesh --check` on several ranks: tests/mpi/spread_check.sh).
bool check_finds_inverted_tet(int rank);
// PARTET_TEST_CHECK_PASS_BYTES=B: the bytes the check on several ranks takes at a time (else
// fallback): a rank's records per pass, and a TetGen file's text per read; so that small meshes
// are checked in many passes and reads too.
double check_pass_bytes(double fallback);
// PARTET_TEST_VERDICT_WAIT_S=S: how long rank 1 waits for the other ranks' findings (else
// fallback); rank 0 waits twice that for rank 1's verdict.
double verdict_wait_seconds(double fallback);
// PARTET_INJECT_FAILURE="worker:abort-before-agreement": rank 1 dies after its last piece, while
// rank 0 writes (the job must then publish nothing).
void worker_death(int rank);

// PARTET_INJECT_FAILURE="worker:lose-block": rank 1 loses its block of an XDMF set's HDF5 files
// or of a TetGen file's rows (as if it ran out of memory taking it), so the write must fail on
// every rank.
bool block_lost(int rank);
// PARTET_INJECT_FAILURE="worker:lose-points": rank 1 loses its share of the input's points that
// rank 0 gives it to format for a single file written from a spread mesh.
bool points_lost(int rank);
// PARTET_INJECT_FAILURE="worker:output-unseen": rank 1 cannot open the files written for
// `mesh --check` on the ranks, as on a node that does not share rank 0's output directory.
bool output_unseen(int rank);

// PARTET_INJECT_FAILURE="worker:write-out-of-memory": rank 1 runs out of memory (std::bad_alloc)
// making its part of a file written from a spread mesh: its rows of a single file streamed to rank
// 0, or a piece or partition file of its own.
void write_out_of_memory(int rank);

// PARTET_INJECT_PUBLISH_FAILURE=N: the N-th new file's move into place fails (0: none).
int publish_failure();
// Called at each step of a publish (0: the journal just written; 1: past its error handling, then
// one per move, then the cleanup). PARTET_TEST_PUBLISH_DELAY_MS=D sleeps D ms first, as a slow
// network filesystem would; PARTET_TEST_PUBLISH_SIGNAL=N:SIG sends signal SIG (a number) to this
// process at step N, then gives its interrupt thread 100 ms to act.
void publish_step(int step);
// PARTET_TEST_PAUSE_BEFORE_PUBLISH_MS=D: sleeps D ms once the files are written, before the
// publish takes its lock (so a test can look at, age or kill the temporaries).
void before_publish();
// PARTET_TEST_PUBLISH_WAIT_S=S: how long a publish waits for another run's lock (else fallback).
double publish_wait_seconds(double fallback);
// Called after a large file's buffer is handed to its writing thread (one per 4 MB).
// PARTET_TEST_WRITE_DELAY_MS=D sleeps D ms, as a slow disk would, so that a test can interrupt
// a run in the middle of a file written around the page cache.
void buffer_handed();

// PARTET_TEST_INTERRUPT_DELAY=RANK:MS: an interrupt's cleanup on that rank (0 alone) starts MS
// later, as on a loaded machine, where a launcher's SIGKILL comes first.
void interrupt_cleanup();

// PARTET_TEST_ASSEMBLE: rank 0 always assembles the mesh, as when a check or a polish reads it
// whole, so that tests can compare the files written from a spread mesh with the assembled path's.
bool assemble_always();
// PARTET_TEST_AVAILABLE_MB: the memory rank 0 finds available when it decides whether to
// assemble the mesh for `mesh --check` (else `measured`): a small value has the ranks check the
// files, as when rank 0 lacks the memory.
double available_mb_for_check(double measured);
// PARTET_TEST_FREE_DISK_MB="A,B,...": the room rank 0 finds on the output's filesystem, A the
// first time it looks (before the meshing), B the next (before the writing), and so on, the last
// again ever after (else `measured`); while it is set, rank 0 looks again every 0.1 s instead of
// disk_poll_seconds. tests/cli/disk_space.sh.
double free_disk_mb(double measured);
// PARTET_TEST_DISK_POLL_S: how often rank 0 looks for room on a real disk that filled up (else
// `fallback`, or 0.1 s with PARTET_TEST_FREE_DISK_MB): tests/cli/full_ext4.sh makes the room
// itself and need not wait the 10 s a user's disk is given.
double disk_poll_seconds(double fallback);
// PARTET_TEST_DISK_CAPACITY_MB: the size of the output's filesystem (else `measured`; negative:
// unknown), as rank 0 finds it with the room PARTET_TEST_FREE_DISK_MB sets.
double disk_capacity_mb(double measured);

// PARTET_TEST_QUOTA_WRITES=N: the first N writes of large files (BufferedFile, any thread) fail
// with EDQUOT, as when a user's quota runs out during the write (errno then; else 0).
int quota_refusal();

// PARTET_TEST_NO_NAMELESS_FILES: the filesystems refuse nameless files (O_TMPFILE), as NFS does.
bool nameless_files_refused();

}  // namespace partet::test_hooks
