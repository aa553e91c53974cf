#include "runner/reaper.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <set>
#include <string>

#include "common/paths.hpp"

namespace partet::reaper {
namespace {

// The pipe's write end (non-blocking: a stopped reaper must never stop the run; a message lost
// then only leaves a file for the next run to remove).
int to_reaper = -1;

// A message: one byte (what), four (the path's length), the path.
enum What : char { kRemember = '+', kForget = '-', kHold = 'h', kRelease = 'r' };

void send(What what, const std::string& path = "") {
  if (to_reaper < 0) return;
  std::string message(1, what);
  const std::uint32_t size = static_cast<std::uint32_t>(path.size());
  message.append(reinterpret_cast<const char*>(&size), sizeof size);
  message += path;
  (void)!::write(to_reaper, message.data(), message.size());  // under PIPE_BUF: whole or not at all
}

// The reaper's life: gather the messages until the pipe closes, then remove the files (unless a
// publish was under way) and end.
[[noreturn]] void reap(int from_partet) {
  std::set<std::string> files;
  bool holding = false;
  std::string pending;
  char buffer[8192];
  for (;;) {
    const ssize_t n = ::read(from_partet, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    pending.append(buffer, static_cast<std::size_t>(n));
    std::size_t at = 0;
    while (pending.size() - at >= 5) {
      std::uint32_t size = 0;
      std::memcpy(&size, pending.data() + at + 1, sizeof size);
      if (pending.size() - at - 5 < size) break;
      const std::string path = pending.substr(at + 5, size);
      switch (pending[at]) {
        case kRemember:
          files.insert(path);
          break;
        case kForget:
          files.erase(path);
          break;
        case kHold:
          holding = true;
          break;
        case kRelease:
          holding = false;
          break;
        default:
          break;
      }
      at += 5 + size;
    }
    pending.erase(0, at);
  }
  if (!holding)
    for (const std::string& f : files) ::unlink(f.c_str());
  ::_exit(0);
}

// In the reaper: nothing of partet's but the pipe, no terminal, deaf to the signals that
// interrupt partet (it ends when partet does).
void become_reaper(int from_partet) {
  ::setsid();
  ::prctl(PR_SET_NAME, "partet-reaper");  // what ps and top show
  for (int s : {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGXCPU, SIGUSR1, SIGUSR2, SIGPIPE, SIGTSTP, SIGTTIN, SIGTTOU})
    ::signal(s, SIG_IGN);
  sigset_t none;
  sigemptyset(&none);
  ::sigprocmask(SIG_SETMASK, &none, nullptr);
  const int null = ::open("/dev/null", O_RDWR);
  for (int fd = 0; fd < 3; ++fd) ::dup2(null, fd);
  // close_range: two calls instead of one close per possible descriptor (65536 of them, about
  // 0.1 s of CPU at every start); the loop where the kernel lacks it (before Linux 5.9).
  const bool closed = from_partet >= 3 && (from_partet == 3 || ::close_range(3, from_partet - 1, 0) == 0) &&
                      ::close_range(from_partet + 1, ~0U, 0) == 0;
  if (!closed) {
    const long open_max = ::sysconf(_SC_OPEN_MAX);
    for (int fd = 3; fd < (open_max > 0 && open_max < 65536 ? open_max : 65536); ++fd)
      if (fd != from_partet) ::close(fd);
  }
  (void)!::chdir("/");  // (the paths it gets are absolute)
}

}  // namespace

void start() {
  if (to_reaper >= 0) return;
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) return;
  // Twice forked: the reaper's parent is init, not partet (partet's children are its TetGen runs).
  // The middle process's exit status says whether the reaper started.
  const pid_t middle = ::fork();
  if (middle == 0) {
    ::close(fds[1]);
    const pid_t reaper = ::fork();
    if (reaper == 0) {
      become_reaper(fds[0]);
      reap(fds[0]);
    }
    ::_exit(reaper > 0 ? 0 : 1);
  }
  ::close(fds[0]);
  int status = 1;
  if (middle > 0)
    while (::waitpid(middle, &status, 0) < 0 && errno == EINTR) {
    }
  if (middle > 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    ::fcntl(fds[1], F_SETFL, O_NONBLOCK);
    to_reaper = fds[1];
  } else {
    ::close(fds[1]);
  }
}

// (The reaper works from "/": it gets absolute paths.)
void remember(const std::string& path) {
  if (to_reaper >= 0) send(kRemember, absolute_path(path));
}

void forget(const std::string& path) {
  if (to_reaper >= 0) send(kForget, absolute_path(path));
}

void hold(bool holding) { send(holding ? kHold : kRelease); }

void close_in_child() {
  if (to_reaper >= 0) ::close(to_reaper);
  to_reaper = -1;
}

}  // namespace partet::reaper
