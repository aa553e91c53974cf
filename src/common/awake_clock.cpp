#include "common/awake_clock.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>

namespace partet {
namespace {

constexpr double kLook = 0.05;  // the watcher's pause between looks, seconds

double steady_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Written by the watching thread alone: pauses first, then the look, so a reader that sees a
// new look also sees its pause (a reader between the two counts a pause twice for a moment:
// its deadlines come later, never sooner).
std::atomic<double> last_look{0}, paused{0};
std::atomic<pid_t> watched_process{0};  // a forked child has no watcher until it asks

void watch() {
  for (;;) {
    std::this_thread::sleep_for(std::chrono::duration<double>(kLook));
    const double now = steady_now(), gap = now - last_look.load();
    if (gap > kLongestUnseenPause) paused.store(paused.load() + gap - kLongestUnseenPause);
    last_look.store(now);
  }
}

void start_watching() {
  const pid_t self = ::getpid();
  pid_t seen = watched_process.load();
  if (seen == self) return;
  last_look.store(steady_now());  // before any thread can read it as this process's
  if (watched_process.compare_exchange_strong(seen, self)) std::thread(watch).detach();  // lives as long as the process
}

}  // namespace

double awake_seconds() {
  start_watching();
  const double look = last_look.load(), pauses = paused.load(), now = steady_now();
  // A pause still going on, or over but not yet seen by the watcher.
  const double unseen = std::max(0.0, now - look - kLongestUnseenPause);
  return now - pauses - unseen;
}

}  // namespace partet
