// The awake clock: a pause of the whole process (SIGSTOP, as a suspended job gets) does not count,
// all but kLongestUnseenPause of it; time spent sleeping or working does.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "common/awake_clock.hpp"

namespace partet {
namespace {

// Runs in a forked child: the awake seconds and the wall seconds over `seconds` of wall time,
// with the child stopped by its parent for `stopped` seconds of it. Figures in milliseconds.
struct Span {
  long awake_ms = 0, wall_ms = 0;
};

Span span_in_child(double seconds, double stopped) {
  int fds[2];
  if (::pipe(fds) != 0) return {};
  const pid_t child = ::fork();
  if (child == 0) {
    ::close(fds[0]);
    const double awake = awake_seconds();
    const auto wall = std::chrono::steady_clock::now();
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
    const Span span{
        static_cast<long>(1000 * (awake_seconds() - awake)),
        static_cast<long>(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall).count())};
    const bool sent = ::write(fds[1], &span, sizeof span) == sizeof span;
    ::_exit(sent ? 0 : 1);
  }
  ::close(fds[1]);
  if (stopped > 0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    ::kill(child, SIGSTOP);
    std::this_thread::sleep_for(std::chrono::duration<double>(stopped));
    ::kill(child, SIGCONT);
  }
  Span span;
  const bool read = ::read(fds[0], &span, sizeof span) == sizeof span;
  ::close(fds[0]);
  int status = 0;
  ::waitpid(child, &status, 0);
  EXPECT_TRUE(read && WIFEXITED(status) && WEXITSTATUS(status) == 0);
  return span;
}

TEST(AwakeClock, SleepingCounts) {
  const Span span = span_in_child(1.5, 0);
  EXPECT_GE(span.wall_ms, 1500);
  EXPECT_GE(span.awake_ms, 1450);
  EXPECT_LE(span.awake_ms, span.wall_ms + 50);
}

TEST(AwakeClock, APauseOfTheWholeProcessDoesNotCount) {
  // Stopped 3 s of the 3.5 s the child waits: it sees its sleep end at once when continued.
  const Span span = span_in_child(0.5, 3);
  EXPECT_GE(span.wall_ms, 3000);
  EXPECT_LE(span.awake_ms, span.wall_ms - 3000 + 1000 * kLongestUnseenPause + 300) << span.wall_ms;
  EXPECT_GE(span.awake_ms, 300);
}

TEST(AwakeClock, WorkCounts) {
  const double awake = awake_seconds();
  const auto wall = std::chrono::steady_clock::now();
  for (volatile long spin = 0; std::chrono::steady_clock::now() - wall < std::chrono::milliseconds(1500);
       spin = spin + 1) {
  }
  EXPECT_GE(awake_seconds() - awake, 1.45);
}

}  // namespace
}  // namespace partet
