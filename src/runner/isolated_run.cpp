#include "runner/isolated_run.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "partet/errors.hpp"
#include "common/awake_clock.hpp"
#include "common/memory.hpp"
#include "common/write_all.hpp"
#include "runner/interrupts.hpp"

namespace partet {
namespace {

// Never above the limit the process inherited: as root it could raise it, and a user's or a
// job's ulimit -v would no longer hold for TetGen.
void limit_memory(double megabytes) {
  rlimit inherited{};
  ::getrlimit(RLIMIT_AS, &inherited);
  const auto limit = static_cast<rlim_t>((virtual_size_mb() + megabytes) * 1024 * 1024);
  rlimit r{};
  r.rlim_cur = r.rlim_max = std::min(limit, inherited.rlim_cur);
  ::setrlimit(RLIMIT_AS, &r);
}

std::chrono::steady_clock::duration steady_seconds(double seconds) {
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
}

// Where memory runs out, the kernel's out-of-memory killer (the node's, or a Slurm job's cgroup's)
// should take this child, which its rank survives (the piece is retried in smaller pieces), not
// a rank, whose death ends the job. Raising one's own score needs no privilege; best effort.
void prefer_for_out_of_memory_kill() {
  const int fd = ::open("/proc/self/oom_score_adj", O_WRONLY | O_CLOEXEC);
  if (fd < 0) return;
  const char first[] = "1000";
  [[maybe_unused]] const ssize_t n = ::write(fd, first, sizeof first - 1);
  ::close(fd);
}

double seconds_of(const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); }

}  // namespace

IsolatedRun::IsolatedRun(const std::function<std::string()>& work, double cpu_seconds, double memory_limit_mb)
    : cpu_limit_(cpu_seconds) {
  wall_deadline_ = awake_seconds() + kWallPerCpuSecond * cpu_seconds;
  cpu_look_ = std::chrono::steady_clock::now() + steady_seconds(cpu_seconds);
  int fds[2];
  if (::pipe(fds) != 0) throw Error(std::string("cannot create a pipe: ") + std::strerror(errno));
  output_fd_ = ::memfd_create("partet-child-output", MFD_CLOEXEC);  // best effort: -1 means no capture
  std::fflush(nullptr);
  const pid_t parent = ::getpid();
  child_ = ::fork();
  if (child_ < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw Error(std::string("cannot fork: ") + std::strerror(errno));
  }
  if (child_ == 0) {
    // The child dies with its parent: a killed rank must not leave TetGen running.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(4);
    prefer_for_out_of_memory_kill();
    // TetGen's assertion text and MPI's crash handlers would only clutter the parent's output.
    ::close(fds[0]);
    interrupts::reset_in_child();  // the parent's interrupt thread is not here; its files are not ours
    // TetGen prints some findings (two facets intersect, with their ids) on stdout even when told
    // to be quiet, and an assertion's text on stderr: they go where the parent can read them (a
    // --quiet run must print nothing).
    const int sink = output_fd_ >= 0 ? output_fd_ : ::open("/dev/null", O_WRONLY);
    if (sink >= 0) {
      ::dup2(sink, STDOUT_FILENO);
      ::dup2(sink, STDERR_FILENO);
    }
    if (memory_limit_mb > 0) limit_memory(memory_limit_mb);
    bool ok = false;
    try {
      // The size first, so the parent can reserve the whole result at once.
      const std::string bytes = work();
      const std::uint64_t size = bytes.size();
      ok = write_all(fds[1], reinterpret_cast<const char*>(&size), sizeof size) &&
           write_all(fds[1], bytes.data(), bytes.size());
    } catch (...) {
    }
    ::close(fds[1]);
    ::_exit(ok ? 0 : 3);
  }
  ::close(fds[1]);
  fd_ = fds[0];
  ::fcntl(fd_, F_SETPIPE_SZ, 1 << 20);  // fewer wake-ups for large results (best effort)
  // Without the child's CPU clock (never seen on Linux) the limit counts wall time.
  has_cpu_clock_ = ::clock_getcpuclockid(child_, &cpu_clock_) == 0;
  if (!has_cpu_clock_) wall_deadline_ -= (kWallPerCpuSecond - 1) * cpu_seconds;
}

IsolatedRun::~IsolatedRun() {
  if (end_ == ProcessEnd::running && child_ > 0) {
    ::kill(child_, SIGKILL);
    int status = 0;
    while (::waitpid(child_, &status, 0) < 0 && errno == EINTR) {
    }
  }
  if (fd_ >= 0) ::close(fd_);
  if (output_fd_ >= 0) ::close(output_fd_);
}

std::string IsolatedRun::output() const {
  if (output_fd_ < 0 || end_ == ProcessEnd::running) return "";
  std::string text(64 * 1024, '\0');
  const ssize_t n = ::pread(output_fd_, text.data(), text.size(), 0);
  text.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
  return text;
}

bool IsolatedRun::poll(int wait_ms) {
  if (end_ != ProcessEnd::running) return true;
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(wait_ms);
  for (;;) {
    const auto now = std::chrono::steady_clock::now();
    // The CPU time first: a child past both limits has had its time.
    const double wall_left = wall_deadline_ - awake_seconds();
    if ((now >= cpu_look_ || wall_left <= 0) && used_its_cpu_time()) {
      finish(ProcessEnd::timed_out);
      return true;
    }
    if (wall_left <= 0) {
      finish(ProcessEnd::stalled);
      return true;
    }
    // Rounded up: a timeout rounded down to 0 ms would make this loop spin until `until`.
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(
        std::min({until, now + steady_seconds(wall_left), cpu_look_}) - now);
    pollfd pfd{fd_, POLLIN, 0};
    const int r = ::poll(&pfd, 1, static_cast<int>(std::max<long long>(0, left.count())));
    if (r < 0 && errno == EINTR) continue;
    if (r == 0) {
      if (std::chrono::steady_clock::now() >= until) return false;
      continue;
    }
    if (!read_available()) {  // end of file: the child has ended
      finish();
      return true;
    }
  }
}

bool IsolatedRun::used_its_cpu_time() {
  timespec used{};
  double left = 0.01;  // a clock that cannot be read (the child just ended?): look again soon
  if (has_cpu_clock_ && ::clock_gettime(cpu_clock_, &used) == 0)
    left = cpu_limit_ - (static_cast<double>(used.tv_sec) + 1e-9 * static_cast<double>(used.tv_nsec));
  if (left <= 0) return true;
  // Looks of a few milliseconds apart would only spin; the limit is met to within 10 ms.
  cpu_look_ = std::chrono::steady_clock::now() + steady_seconds(std::max(left, 0.01));
  return false;
}

bool IsolatedRun::read_available() {
  constexpr std::size_t kHeader = sizeof(std::uint64_t);
  char spare[4096];
  char* target;
  std::size_t room;
  if (header_.size() < kHeader) {
    target = spare;
    room = kHeader - header_.size();
  } else if (filled_ < received_.size()) {
    target = received_.data() + filled_;
    room = std::min<std::size_t>(received_.size() - filled_, std::size_t{1} << 20);
  } else {
    target = spare;  // everything announced has arrived: only the end of the pipe should follow
    room = sizeof spare;
  }
  const ssize_t n = ::read(fd_, target, room);
  if (n < 0 && errno == EINTR) return true;
  if (n <= 0) return false;
  if (header_.size() < kHeader) {
    header_.append(spare, static_cast<std::size_t>(n));
    if (header_.size() == kHeader) {
      std::uint64_t size = 0;
      std::memcpy(&size, header_.data(), kHeader);
      received_.resize(size);
    }
  } else if (target == spare) {
    overflow_ = true;  // more than announced: not a valid result
  } else {
    filled_ += static_cast<std::size_t>(n);
  }
  return true;
}

void IsolatedRun::wait() {
  while (!poll(1000)) {
  }
}

void IsolatedRun::finish(ProcessEnd killed_for) {
  ::close(fd_);
  fd_ = -1;
  if (killed_for != ProcessEnd::running) ::kill(child_, SIGKILL);
  int status = 0;
  rusage usage{};
  while (::wait4(child_, &status, 0, &usage) < 0 && errno == EINTR) {
  }
  peak_mb_ = static_cast<double>(usage.ru_maxrss) / 1024.0;
  cpu_seconds_ = seconds_of(usage.ru_utime) + seconds_of(usage.ru_stime);
  if (killed_for != ProcessEnd::running) {
    end_ = killed_for;
  } else if (WIFSIGNALED(status)) {
    end_ = ProcessEnd::crashed;
    signal_ = WTERMSIG(status);
  } else if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || header_.size() != sizeof(std::uint64_t) ||
             filled_ != received_.size() || overflow_) {
    end_ = ProcessEnd::no_result;
  } else {
    end_ = ProcessEnd::finished;
    return;
  }
  received_.clear();
  received_.shrink_to_fit();
}

}  // namespace partet
