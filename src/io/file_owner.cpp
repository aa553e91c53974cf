#include "io/file_owner.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <random>
#include <sstream>

namespace partet {
namespace {

std::string first_line(const char* path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

std::string link_target(const char* path) {
  char text[256];
  const ssize_t n = ::readlink(path, text, sizeof text - 1);
  return n > 0 ? std::string(text, static_cast<std::size_t>(n)) : std::string();
}

// Seconds since the epoch at which this host booted.
double boot_time() {
  std::ifstream in("/proc/stat");
  std::string key;
  double value = 0;
  while (in >> key) {
    if (key == "btime" && (in >> value)) return value;
    in.ignore(1 << 16, '\n');
  }
  return 0;
}

// When process pid started (seconds since the epoch), or a negative value when it does not run.
double process_start(long pid) {
  const std::string text = first_line(("/proc/" + std::to_string(pid) + "/stat").c_str());
  const auto close = text.rfind(')');  // the command name may hold spaces and parentheses
  if (close == std::string::npos) return -1;
  std::istringstream fields(text.substr(close + 2));
  std::string field;
  char state = 0;
  fields >> state;
  if (state == 'Z' || state == 'X') return -1;  // ended, waiting to be reaped
  for (int i = 4; i <= 22 && fields >> field; ++i)
    if (i == 22) return boot_time() + std::strtod(field.c_str(), nullptr) / static_cast<double>(::sysconf(_SC_CLK_TCK));
  return -1;
}

double modification_time(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return -1;
  return static_cast<double>(st.st_mtim.tv_sec) + 1e-9 * static_cast<double>(st.st_mtim.tv_nsec);
}

}  // namespace

const std::string& host_tag() {
  static const std::string tag = [] {
    char name[256] = {};
    ::gethostname(name, sizeof name - 1);
    // The hostname alone does not tell containers, or a rebooted node, apart.
    const std::string identity = std::string(name) + "|" + first_line("/proc/sys/kernel/random/boot_id") + "|" +
                                 link_target("/proc/self/ns/pid");
    std::uint32_t h = 2166136261u;
    for (unsigned char c : identity) h = (h ^ c) * 16777619u;
    char text[9];
    std::snprintf(text, sizeof text, "%08x", h);
    return std::string(text);
  }();
  return tag;
}

std::string temporary_suffix() {
  std::random_device device;
  char text[64];
  std::snprintf(text, sizeof text, ".tmp-%ld-%s-%08x", static_cast<long>(::getpid()), host_tag().c_str(), device());
  return text;
}

bool parse_temporary_suffix(const std::string& name, long& pid, std::string& host) {
  const auto at = name.rfind(".tmp-");
  if (at == std::string::npos) return false;
  const std::string rest = name.substr(at + 5);  // <pid>-<host>-<random>
  const auto dash1 = rest.find('-'), dash2 = rest.rfind('-');
  if (dash1 == std::string::npos || dash2 != dash1 + 9 || rest.size() != dash2 + 9) return false;
  char* end = nullptr;
  pid = std::strtol(rest.c_str(), &end, 10);
  if (end != rest.c_str() + dash1 || pid <= 0) return false;
  host = rest.substr(dash1 + 1, 8);
  return true;
}

bool OwnedFile::create(const std::string& path) {
  close();
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd_ < 0) return false;
  lock_ = try_lock(fd_);  // without locks (some network filesystems) the name still says who owns it
  return true;
}

OwnedFile::~OwnedFile() { close(); }

OwnedFile& OwnedFile::operator=(OwnedFile&& other) noexcept {
  if (this != &other) {
    close();
    fd_ = other.fd_;
    lock_ = other.lock_;
    other.fd_ = -1;
  }
  return *this;
}

void OwnedFile::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

LockTry try_lock(int fd) {
  struct flock lock {};
  lock.l_type = F_WRLCK;
  lock.l_whence = SEEK_SET;
  if (::fcntl(fd, F_OFD_SETLK, &lock) == 0) return LockTry::acquired;
  if (errno == EAGAIN || errno == EACCES) return LockTry::held_elsewhere;
  if (errno == EINVAL) {  // a kernel without open file description locks
    if (::flock(fd, LOCK_EX | LOCK_NB) == 0) return LockTry::acquired;
    if (errno == EWOULDBLOCK) return LockTry::held_elsewhere;
  }
  return LockTry::unsupported;
}

bool process_runs(long pid, double not_after) {
  const double start = process_start(pid);
  // A pid taken by a process that started after the file was made belongs to someone else.
  return start >= 0 && start <= not_after + 2;
}

bool temporary_owner_gone(const std::string& path) {
  long pid = 0;
  std::string host;
  if (!parse_temporary_suffix(path, pid, host)) return false;
  const double made = modification_time(path);
  if (made < 0) return false;
  if (host == host_tag()) return !process_runs(pid, made);
  // Another host (or container): only its lock can tell. A file made a moment ago may not be
  // locked yet.
  if (static_cast<double>(std::time(nullptr)) - made < 60) return false;
  const int fd = ::open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return false;
  const bool gone = try_lock(fd) == LockTry::acquired;
  ::close(fd);  // releases the lock taken to test it
  return gone;
}

}  // namespace partet
