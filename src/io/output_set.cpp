#include "partet/output_set.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <random>

#include "partet/errors.hpp"

namespace partet {
namespace {

namespace fs = std::filesystem;

// Temporaries the interrupt handler removes: plain arrays, readable from a signal handler.
constexpr int kMaxTemporaries = 64;
char g_temporaries[kMaxTemporaries][4096];
volatile sig_atomic_t g_temporary_count = 0;
char g_interrupt_message[512];

void remember_temporaries(const std::vector<std::string>& paths) {
  g_temporary_count = 0;
  int n = 0;
  for (const std::string& p : paths) {
    if (n == kMaxTemporaries || p.size() >= sizeof g_temporaries[0]) continue;
    std::memcpy(g_temporaries[n], p.c_str(), p.size() + 1);
    ++n;
  }
  g_temporary_count = n;
}

extern "C" void on_interrupt(int signal_number) {
  for (int i = 0; i < g_temporary_count; ++i) ::unlink(g_temporaries[i]);
  if (g_interrupt_message[0]) {
    char text[640];
    const int n = std::snprintf(text, sizeof text, "%s (signal %d)\n", g_interrupt_message, signal_number);
    if (n > 0) (void)!::write(STDERR_FILENO, text, static_cast<std::size_t>(n));
  }
  ::_exit(128 + signal_number);
}

std::string directory_of(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  return parent.empty() ? "." : parent.string();
}

// Holds an exclusive lock on a directory: publishes into it happen one at a time.
class DirectoryLock {
 public:
  explicit DirectoryLock(const std::string& directory) : fd_(::open(directory.c_str(), O_RDONLY | O_DIRECTORY)) {
    if (fd_ >= 0) ::flock(fd_, LOCK_EX);
  }
  ~DirectoryLock() {
    if (fd_ >= 0) ::close(fd_);  // releases the lock
  }
  DirectoryLock(const DirectoryLock&) = delete;
  DirectoryLock& operator=(const DirectoryLock&) = delete;

 private:
  int fd_;
};

// Test hook: PARTET_INJECT_PUBLISH_FAILURE=N makes the N-th new file's move into place fail
// (N from 1), as an immutable target or an I/O error would.
int injected_publish_failure() {
  const char* spec = std::getenv("PARTET_INJECT_PUBLISH_FAILURE");
  return spec ? std::atoi(spec) : 0;
}

[[noreturn]] void refuse(const std::string& path, const std::string& why) {
  throw OutputError("cannot write '" + path + "': " + why);
}

}  // namespace

OutputSet::OutputSet() {
  std::random_device device;
  char text[64];
  std::snprintf(text, sizeof text, ".tmp-%ld-%08x", static_cast<long>(::getpid()), device());
  suffix_ = text;
}

OutputSet::~OutputSet() {
  if (!published_) discard();
}

void OutputSet::add(const std::string& final_path, const std::function<void(const std::string&)>& write_file) {
  const std::string temporary = final_path + suffix_;
  finals_.push_back(final_path);
  temporaries_.push_back(temporary);
  remember_temporaries(temporaries_);
  try {
    write_file(temporary);
  } catch (...) {
    discard();
    throw;
  }
}

void OutputSet::discard() {
  for (const std::string& t : temporaries_) std::remove(t.c_str());
  temporaries_.clear();
  finals_.clear();
  remember_temporaries({});
}

void OutputSet::publish() {
  if (finals_.empty()) return;
  DirectoryLock lock(directory_of(finals_.front()));
  // 1. The previous files step aside; 2. the new ones move in; a failure undoes both.
  std::vector<std::string> moved_aside, moved_in;
  auto undo = [&] {
    for (const std::string& f : moved_in) std::remove(f.c_str());
    for (const std::string& f : moved_aside) std::rename((f + ".old" + suffix_).c_str(), f.c_str());
  };
  for (std::size_t i = 0; i < finals_.size(); ++i) {
    const std::string f = finals_[i];  // a copy: discard() clears finals_ before refuse() names it
    std::error_code ec;
    if (!fs::exists(fs::symlink_status(f, ec))) continue;
    if (!fs::is_regular_file(fs::symlink_status(f, ec))) {  // never move a directory or a device aside
      undo();
      discard();
      refuse(f, "it exists and is not a regular file");
    }
    if (std::rename(f.c_str(), (f + ".old" + suffix_).c_str()) != 0) {
      const std::string reason = std::strerror(errno);
      undo();
      discard();
      refuse(f, reason);
    }
    moved_aside.push_back(f);
  }
  const int inject = injected_publish_failure();
  for (std::size_t i = 0; i < finals_.size(); ++i) {
    if (static_cast<int>(i) + 1 == inject) errno = EIO;
    if (static_cast<int>(i) + 1 == inject || std::rename(temporaries_[i].c_str(), finals_[i].c_str()) != 0) {
      const std::string reason = std::strerror(errno), failed = finals_[i];
      undo();
      discard();
      refuse(failed, reason + " (the previous files are left as they were)");
    }
    moved_in.push_back(finals_[i]);
  }
  for (const std::string& f : moved_aside) std::remove((f + ".old" + suffix_).c_str());
  published_ = true;
  temporaries_.clear();
  remember_temporaries({});
}

void check_output_paths(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs) {
  std::vector<std::pair<std::string, std::string>> seen;  // (normalized path, as given)
  auto normalized = [](const std::string& p) {
    std::error_code ec;
    const fs::path n = fs::weakly_canonical(fs::absolute(p, ec), ec);
    return ec ? p : n.string();
  };
  for (const std::string& p : inputs) seen.push_back({normalized(p), p});
  for (const std::string& p : outputs) {
    if (p.empty()) throw OutputError("an output path is empty");
    if (p.back() == '/' || fs::is_directory(p)) refuse(p, "it is a directory (give a file name)");
    std::error_code ec;
    if (fs::exists(p, ec) && !fs::is_regular_file(p, ec)) refuse(p, "it exists and is not a regular file");
    const std::string directory = directory_of(p);
    if (!fs::is_directory(directory, ec)) refuse(p, "directory '" + directory + "' does not exist");
    if (::access(directory.c_str(), W_OK | X_OK) != 0) refuse(p, "directory '" + directory + "' is not writable");
    const std::string n = normalized(p);
    for (const auto& [other, given] : seen)
      if (other == n) refuse(p, "it is the same file as '" + given + "'");
    seen.push_back({n, p});
  }
}

void remove_stale_temporaries(const std::vector<std::string>& final_paths) {
  for (const std::string& f : final_paths) {
    const std::string directory = directory_of(f), prefix = fs::path(f).filename().string() + ".tmp-";
    DIR* dir = ::opendir(directory.c_str());
    if (!dir) continue;
    while (const dirent* entry = ::readdir(dir)) {
      const std::string name = entry->d_name;
      if (name.compare(0, prefix.size(), prefix) != 0) continue;
      const long pid = std::strtol(name.c_str() + prefix.size(), nullptr, 10);
      if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH)
        std::remove((directory + "/" + name).c_str());
    }
    ::closedir(dir);
  }
}

void install_interrupt_handler(const std::string& message) {
  std::snprintf(g_interrupt_message, sizeof g_interrupt_message, "%s", message.c_str());
  struct sigaction action {};
  action.sa_handler = on_interrupt;
  sigemptyset(&action.sa_mask);
  ::sigaction(SIGINT, &action, nullptr);
  ::sigaction(SIGTERM, &action, nullptr);
}

}  // namespace partet
