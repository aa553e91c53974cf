#include "process/isolated_run.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "partet/errors.hpp"

namespace partet {
namespace {

bool write_all(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace

IsolatedRun::IsolatedRun(const std::function<std::string()>& work, double timeout_seconds)
    : timeout_seconds_(timeout_seconds),
      deadline_(std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                       std::chrono::duration<double>(timeout_seconds))) {
  int fds[2];
  if (::pipe(fds) != 0) throw Error(std::string("cannot create a pipe: ") + std::strerror(errno));
  std::fflush(nullptr);
  child_ = ::fork();
  if (child_ < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw Error(std::string("cannot fork: ") + std::strerror(errno));
  }
  if (child_ == 0) {
    // TetGen's assertion text and MPI's crash handlers would only clutter the parent's output.
    ::close(fds[0]);
    ::signal(SIGABRT, SIG_DFL);
    ::signal(SIGSEGV, SIG_DFL);
    ::signal(SIGBUS, SIG_DFL);
    if (const int devnull = ::open("/dev/null", O_WRONLY); devnull >= 0) ::dup2(devnull, STDERR_FILENO);
    bool ok = false;
    try {
      const std::string bytes = work();
      ok = write_all(fds[1], bytes.data(), bytes.size());
    } catch (...) {
    }
    ::close(fds[1]);
    ::_exit(ok ? 0 : 3);
  }
  ::close(fds[1]);
  fd_ = fds[0];
}

IsolatedRun::~IsolatedRun() {
  if (end_ == ProcessEnd::running && child_ > 0) {
    ::kill(child_, SIGKILL);
    int status = 0;
    while (::waitpid(child_, &status, 0) < 0 && errno == EINTR) {
    }
  }
  if (fd_ >= 0) ::close(fd_);
}

bool IsolatedRun::poll(int wait_ms) {
  if (end_ != ProcessEnd::running) return true;
  char buffer[1 << 16];
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(wait_ms);
  for (;;) {
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline_) {
      finish(true);
      return true;
    }
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(std::min(until, deadline_) - now);
    pollfd pfd{fd_, POLLIN, 0};
    const int r = ::poll(&pfd, 1, static_cast<int>(std::max<long long>(0, left.count())));
    if (r < 0 && errno == EINTR) continue;
    if (r == 0) {
      if (std::chrono::steady_clock::now() >= until) return false;
      continue;
    }
    const ssize_t n = ::read(fd_, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {  // end of file: the child has finished
      finish(false);
      return true;
    }
    received_.append(buffer, static_cast<std::size_t>(n));
  }
}

void IsolatedRun::wait() {
  while (!poll(1000)) {
  }
}

void IsolatedRun::finish(bool timed_out) {
  ::close(fd_);
  fd_ = -1;
  if (timed_out) ::kill(child_, SIGKILL);
  int status = 0;
  while (::waitpid(child_, &status, 0) < 0 && errno == EINTR) {
  }
  if (timed_out) {
    end_ = ProcessEnd::timed_out;
  } else if (WIFSIGNALED(status)) {
    end_ = ProcessEnd::crashed;
    signal_ = WTERMSIG(status);
  } else if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    end_ = ProcessEnd::no_result;
  } else {
    end_ = ProcessEnd::finished;
    return;
  }
  received_.clear();
  received_.shrink_to_fit();
}

}  // namespace partet
