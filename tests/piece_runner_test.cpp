// The piece runner: the same results in this process and in an isolated child, and every way
// a run can end (error, crash, time limit) as a typed failure.
#include <gtest/gtest.h>

#include <csignal>

#include <dirent.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "common/memory.hpp"
#include "io/file_owner.hpp"
#include "stages/closure.hpp"
#include "partet/errors.hpp"
#include "stages/generate.hpp"
#include "stages/partition.hpp"
#include "stages/piece.hpp"
#include "runner/isolated_run.hpp"
#include "runner/piece_checkpoint.hpp"
#include "runner/piece_runner.hpp"
#include "runner/serialize.hpp"
#include "stage_batches.hpp"

namespace partet {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

PieceRunner runner(bool isolate, double timeout = 0, const std::string& quality = "") {
  TetgenOptions tetgen;
  tetgen.quality = quality;
  RunOptions run;
  run.isolate = isolate;
  run.timeout_seconds = timeout;
  return PieceRunner(tetgen, run);
}

std::vector<PieceSurface> torus_pieces() {
  const SurfaceMesh s = generate_surface("torus", 2000);
  const auto planes = choose_cut_planes(s, 3);
  SplitSurface split = split_at_planes(s, planes);
  return assemble_pieces(split, build_caps(split, planes, 1.0));
}

PieceSurface open_piece() {
  PieceSurface piece;
  piece.index = 3;
  const SurfaceMesh s = generate_surface("sphere", 500);
  piece.points = s.points;
  piece.triangles.assign(s.triangles.begin() + 1, s.triangles.end());
  for (std::size_t i = 0; i < s.points.size(); ++i) piece.global_ids.push_back(static_cast<std::int32_t>(i));
  return piece;
}

TEST(PieceRunner, ChildGivesTheSameResultAsThisProcess) {
  for (const auto& piece : torus_pieces()) {
    SCOPED_TRACE("piece " + std::to_string(piece.index));
    const PieceOutcome here = runner(false, 0, "1.5").mesh(piece);
    const PieceOutcome child = runner(true, 0, "1.5").mesh(piece);
    ASSERT_FALSE(here.failure) << here.failure->text();
    ASSERT_FALSE(child.failure) << child.failure->text();
    EXPECT_EQ(here.result.index, piece.index);
    EXPECT_EQ(child.result.index, piece.index);
    EXPECT_EQ(here.result.surface_point_count, child.result.surface_point_count);
    EXPECT_EQ(here.result.mesh.tets, child.result.mesh.tets);
    EXPECT_EQ(here.result.mesh.neighbours, child.result.mesh.neighbours);
    EXPECT_EQ(here.result.mesh.steiner_points, child.result.mesh.steiner_points);
  }
}

TEST(PieceRunner, BadPieceIsATypedFailureInBothModes) {
  const PieceSurface piece = open_piece();
  for (bool isolate : {false, true}) {
    SCOPED_TRACE(isolate ? "isolated" : "in process");
    const PieceOutcome outcome = runner(isolate).mesh(piece);
    ASSERT_TRUE(outcome.failure);
    EXPECT_EQ(outcome.failure->kind, FailureKind::bad_surface);
    EXPECT_EQ(outcome.failure->piece, 3);
    EXPECT_NE(outcome.failure->text().find("piece 3: "), std::string::npos) << outcome.failure->text();
  }
}

TEST(PieceRunner, AChildPrintsNothing) {
  // TetGen prints some findings ("Found two facets intersect each other.") on stdout even with
  // -Q, and under mpirun stdout is line-buffered, so they would reach the user mid-run. The hook
  // runs where TetGen runs and prints the same way (flushed, as a line-buffered stream is).
  const PieceSurface piece = torus_pieces()[0];
  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  const std::string reply = runner(true).mesh_to_reply(piece, [] {
    std::printf("Found two facets intersect each other.\n");
    std::fflush(stdout);
    std::fprintf(stderr, "terminate called after throwing an instance of 'int'\n");
  });
  const std::string out = testing::internal::GetCapturedStdout();
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_FALSE(deserialize_outcome(reply).failure);
  EXPECT_EQ(out, "");
  EXPECT_EQ(err, "");
}

TEST(PieceRunner, TimeLimitIsATypedFailure) {
  const auto pieces = torus_pieces();
  const PieceOutcome outcome = runner(true, 1e-6).mesh(pieces[0]);
  ASSERT_TRUE(outcome.failure);
  EXPECT_EQ(outcome.failure->kind, FailureKind::timed_out);
  EXPECT_NE(outcome.failure->text().find("did not finish"), std::string::npos) << outcome.failure->text();
}

// The limit counts CPU time: a child that waits for a core (here: sleeps) longer than its limit,
// as beside a neighbouring job, still gives its result, so the outcome does not depend on the
// load.
TEST(PieceRunner, TimeWaitingForACoreDoesNotCount) {
  const auto pieces = torus_pieces();
  const auto start = std::chrono::steady_clock::now();
  const PieceOutcome outcome = deserialize_outcome(runner(true, 1).mesh_to_reply(pieces[0], [] {
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  }));
  EXPECT_GE(seconds_since(start), 1.5);
  ASSERT_FALSE(outcome.failure) << outcome.failure->text();
  EXPECT_FALSE(outcome.result.mesh.tets.empty());
}

TEST(PieceRunner, ChildUsingItsCpuTimeIsStopped) {
  const auto pieces = torus_pieces();
  const auto start = std::chrono::steady_clock::now();
  const PieceOutcome outcome = deserialize_outcome(runner(true, 0.3).mesh_to_reply(pieces[0], [] {
    for (volatile unsigned spin = 0;; spin = spin + 1) {
    }
  }));
  const double seconds = seconds_since(start);
  ASSERT_TRUE(outcome.failure);
  EXPECT_EQ(outcome.failure->kind, FailureKind::timed_out);
  EXPECT_NE(outcome.failure->text().find("did not finish within its 0.3 s of CPU time"), std::string::npos)
      << outcome.failure->text();
  EXPECT_GE(seconds, 0.3);
  EXPECT_LT(seconds, 0.3 * kWallPerCpuSecond);  // ended by its CPU time, not by the wall time
}

// A child that cannot run at all (stopped, or a machine overloaded past kWallPerCpuSecond) still
// ends, and the message says why.
TEST(PieceRunner, ChildThatCannotRunEndsAtItsWallTime) {
  const auto pieces = torus_pieces();
  const auto start = std::chrono::steady_clock::now();
  const PieceOutcome outcome = deserialize_outcome(runner(true, 0.3).mesh_to_reply(pieces[0], [] {
    for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
  }));
  ASSERT_TRUE(outcome.failure);
  EXPECT_EQ(outcome.failure->kind, FailureKind::timed_out);
  EXPECT_NE(outcome.failure->text().find("did not finish within 1 s, having used 0.0 of its 0.3 s of CPU time: its process "
                                         "was stopped, or the machine is overloaded"),
            std::string::npos)
      << outcome.failure->text();
  EXPECT_GE(seconds_since(start), 0.3 * kWallPerCpuSecond);
}

TEST(PieceRunner, CrashAndHookFailuresInAChild) {
  const auto pieces = torus_pieces();
  const PieceRunner isolated = runner(true);
  const std::string crash = isolated.mesh_to_reply(pieces[1], [] { std::abort(); });
  const PieceOutcome crashed = deserialize_outcome(crash);
  ASSERT_TRUE(crashed.failure);
  EXPECT_EQ(crashed.failure->kind, FailureKind::crashed);
  EXPECT_EQ(crashed.failure->piece, 1);
  EXPECT_NE(crashed.failure->text().find("crashed (signal 6"), std::string::npos) << crashed.failure->text();
  // Killed from outside (as the out-of-memory killer does): the message says what most often does
  // that and what helps.
  const PieceOutcome killed = deserialize_outcome(isolated.mesh_to_reply(pieces[1], [] { ::raise(SIGKILL); }));
  ASSERT_TRUE(killed.failure);
  EXPECT_EQ(killed.failure->kind, FailureKind::killed);
  EXPECT_NE(killed.failure->text().find("crashed (signal 9: killed from outside, most often by the out-of-memory killer"),
            std::string::npos)
      << killed.failure->text();
  EXPECT_NE(killed.failure->text().find("more --pieces"), std::string::npos) << killed.failure->text();

  const PieceOutcome injected = deserialize_outcome(
      isolated.mesh_to_reply(pieces[2], [] { throw MeshingError(FailureKind::injected, 2, "injected"); }));
  ASSERT_TRUE(injected.failure);
  EXPECT_EQ(injected.failure->kind, FailureKind::injected);
  EXPECT_EQ(injected.failure->piece, 2);
}

// Under an address-space limit the process inherited (ulimit -v, a job's virtual memory limit)
// below partet's own, running out of memory is the piece's size, not a runaway refinement: more
// pieces help (out_of_memory), and the child keeps that lower limit even where it could raise it
// (root). Without such a limit the same allocation is a runaway under partet's own limit.
TEST(PieceRunner, UnderAnInheritedMemoryLimitAPieceRunsOutOfMemoryItDoesNotRunAway) {
  const auto pieces = torus_pieces();
  const auto allocate_much = [] {
    std::vector<char> much(std::size_t{1} << 31, 1);
    if (much[12345] != 1) std::abort();
  };
  const PieceOutcome unlimited = deserialize_outcome(runner(true).mesh_to_reply(pieces[0], allocate_much));
  ASSERT_TRUE(unlimited.failure);
  EXPECT_EQ(unlimited.failure->kind, FailureKind::runaway) << unlimited.failure->text();

  const pid_t pid = ::fork();
  if (pid == 0) {  // a process under a limit of its own, 48 MB above what it maps now
    rlimit limit{};
    limit.rlim_cur = limit.rlim_max = static_cast<rlim_t>((virtual_size_mb() + 48) * 1024 * 1024);
    if (::setrlimit(RLIMIT_AS, &limit) != 0) ::_exit(10);
    const PieceOutcome limited = deserialize_outcome(runner(true).mesh_to_reply(pieces[0], allocate_much));
    if (!limited.failure || limited.failure->kind != FailureKind::out_of_memory) ::_exit(11);
    const std::string text = limited.failure->text();
    if (text.find("ran out of memory under the address-space limit this process inherited (ulimit -v") ==
            std::string::npos ||
        text.find("more --pieces make each smaller, or raise the limit") == std::string::npos)
      ::_exit(12);
    IsolatedRun child(
        [] {
          rlimit in_child{};
          ::getrlimit(RLIMIT_AS, &in_child);
          return std::to_string(in_child.rlim_cur);
        },
        10, 100000);
    child.wait();
    ::_exit(child.end() == ProcessEnd::finished && std::stoull(child.take_bytes()) <= limit.rlim_cur ? 0 : 13);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "10: no limit set, 11: not out_of_memory, 12: its message, 13: the child's limit";
}

// The out-of-memory killer takes a meshing child first (its rank survives and retries smaller
// pieces), never a rank before it.
TEST(IsolatedRun, TheChildIsTheOutOfMemoryKillersFirstChoice) {
  IsolatedRun run(
      [] {
        std::ifstream in("/proc/self/oom_score_adj");
        std::string adj;
        in >> adj;
        return adj;
      },
      10);
  run.wait();
  ASSERT_EQ(run.end(), ProcessEnd::finished);
  EXPECT_EQ(run.take_bytes(), "1000");
  std::ifstream own("/proc/self/oom_score_adj");
  int adj = 0;
  own >> adj;
  EXPECT_LT(adj, 1000);  // this process (a rank) is left as it was
}

TEST(PieceRunner, BackgroundJobsCanBePolled) {
  const auto pieces = torus_pieces();
  auto job = runner(true).start(pieces[0]);
  while (!job->poll(10)) {
  }
  const PieceOutcome outcome = deserialize_outcome(job->take_reply());
  EXPECT_FALSE(outcome.failure);
  EXPECT_FALSE(outcome.result.mesh.tets.empty());
  EXPECT_TRUE(runner(true).runs_in_background());
  EXPECT_FALSE(runner(false).runs_in_background());
}

TEST(PieceCheckpoint, KeepsResultsOnlyAndTakesOnlyTheSameInput) {
  const auto pieces = torus_pieces();
  char pattern[] = "/tmp/partet-checkpoint-XXXXXX";
  ASSERT_NE(::mkdtemp(pattern), nullptr);
  const std::string dir = pattern, first = dir + "/first", second = dir + "/second";
  RunOptions run;
  run.checkpoint = first;
  const PieceRunner keeping(TetgenOptions{}, run);
  // A failure is not kept; a result is, and a second run takes it (figures 0: nothing ran).
  EXPECT_TRUE(keeping.mesh(open_piece()).failure);
  const PieceOutcome meshed = keeping.mesh(pieces[1]);
  ASSERT_FALSE(meshed.failure);
  const auto files = [](const std::string& d) {
    std::vector<std::string> names;
    if (DIR* handle = ::opendir(d.c_str())) {
      while (const dirent* entry = ::readdir(handle))
        if (entry->d_name[0] != '.') names.push_back(entry->d_name);
      ::closedir(handle);
    }
    return names;
  };
  ASSERT_EQ(files(first).size(), 1u);
  const PieceOutcome taken = keeping.mesh(pieces[1]);
  ASSERT_FALSE(taken.failure);
  EXPECT_EQ(taken.result.mesh.tets, meshed.result.mesh.tets);
  EXPECT_EQ(taken.result.mesh.steiner_points, meshed.result.mesh.steiner_points);
  EXPECT_EQ(taken.seconds, 0);
  // Another input under the same name (a hash collision): not taken.
  const PieceCheckpoint checkpoint(second);
  const std::string key = PieceCheckpoint::key_of(pieces[2], TetgenOptions{});
  checkpoint.keep(key, 2, runner(false).mesh_to_reply(pieces[2]));
  ASSERT_EQ(files(second).size(), 1u);
  const std::string other = second + "/" + files(second).front();
  ASSERT_EQ(std::rename((first + "/" + files(first).front()).c_str(), other.c_str()), 0);
  EXPECT_FALSE(checkpoint.find(key, 2));
  // Other TetGen options: not taken.
  TetgenOptions quality;
  quality.quality = "1.5";
  EXPECT_FALSE(PieceCheckpoint(first).find(PieceCheckpoint::key_of(pieces[1], quality), 1));
  std::filesystem::remove_all(dir);
}

// What a killed run was writing goes when the next run starts; what a live run (on this host or
// another, which only its lock tells) is writing stays, however old; a DIR that is a file is
// refused.
TEST(PieceCheckpoint, ADeadRunsTemporariesGoALiveRunsStay) {
  char pattern[] = "/tmp/partet-checkpoint-XXXXXX";
  ASSERT_NE(::mkdtemp(pattern), nullptr);
  const std::string dir = pattern;
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  ASSERT_EQ(::waitpid(child, nullptr, 0), child);
  const std::string other_host = host_tag() == "00000000" ? "00000001" : "00000000";
  const auto temporary = [&](long pid, const std::string& host) {
    return dir + "/piece-3-00000000000000ab.bin.tmp-" + std::to_string(pid) + "-" + host + "-0000abcd";
  };
  const std::string dead = temporary(child, host_tag()), living = temporary(::getpid(), host_tag());
  const std::string elsewhere_dead = temporary(child, other_host);
  const std::string elsewhere_new = temporary(child + 1, other_host);
  const std::string elsewhere_locked = temporary(child + 2, other_host);
  const std::string kept = dir + "/piece-3-00000000000000ab.bin";
  for (const std::string& path : {dead, living, elsewhere_dead, elsewhere_new, elsewhere_locked, kept})
    std::ofstream(path) << "x";
  const auto long_ago = std::filesystem::file_time_type::clock::now() - std::chrono::minutes(10);
  for (const std::string& path : {dead, elsewhere_dead, elsewhere_locked, kept})
    std::filesystem::last_write_time(path, long_ago);
  // Another description of the file holds the lock, as the writing run's would.
  const int holder = ::open(elsewhere_locked.c_str(), O_RDWR | O_CLOEXEC);
  ASSERT_GE(holder, 0);
  ASSERT_EQ(try_lock(holder), LockTry::acquired);
  check_checkpoint_directory(dir);
  ::close(holder);
  EXPECT_FALSE(std::filesystem::exists(dead));
  EXPECT_TRUE(std::filesystem::exists(living));
  EXPECT_FALSE(std::filesystem::exists(elsewhere_dead));
  EXPECT_TRUE(std::filesystem::exists(elsewhere_new));  // not yet locked, maybe
  EXPECT_TRUE(std::filesystem::exists(elsewhere_locked));
  EXPECT_TRUE(std::filesystem::exists(kept));
  try {
    check_checkpoint_directory(kept);
    ADD_FAILURE() << "a file taken for the checkpoint directory";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("is not a directory"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace partet
