// Files a run owns on a filesystem other runs share, maybe from other nodes: temporaries and the
// publish journal. The owner holds a lock on each while it lives, and their names say which host
// and process made them, so a later run can tell a dead run's leftovers from a live run's files
// and never touches the latter (internal header).
#pragma once
#include <string>

namespace partet {

// ".tmp-<pid>-<host>-<random>": unique to this run; <host> is 8 hex digits naming this host, its
// boot and its PID namespace (two containers or nodes with the same hostname differ).
std::string temporary_suffix();
// Whether a file name ends with a suffix of that form; gives the pid and host parts.
bool parse_temporary_suffix(const std::string& name, long& pid, std::string& host);
// This host's 8 hex digits.
const std::string& host_tag();

enum class LockTry { acquired, held_elsewhere, unsupported };
// Tries to lock an open file (write lock, whole file, without waiting).
LockTry try_lock(int fd);

// A file this run created and locks for as long as the object lives (an open file description
// lock, which NFS carries to the server; where the filesystem has no locks, the name alone
// tells).
class OwnedFile {
 public:
  OwnedFile() = default;
  // Creates path exclusively (false with errno set when it exists) and tries to lock it.
  bool create(const std::string& path);
  // How locking it went.
  LockTry lock() const { return lock_; }
  ~OwnedFile();
  OwnedFile(OwnedFile&& other) noexcept : fd_(other.fd_), lock_(other.lock_) { other.fd_ = -1; }
  OwnedFile& operator=(OwnedFile&& other) noexcept;
  OwnedFile(const OwnedFile&) = delete;
  OwnedFile& operator=(const OwnedFile&) = delete;
  int fd() const { return fd_; }
  void close();

 private:
  int fd_ = -1;
  LockTry lock_ = LockTry::unsupported;
};

// Whether the run that made `path` (a temporary named by temporary_suffix) is gone for sure: on
// this host its process no longer runs (or its pid now names a process started after the file
// was made); elsewhere nobody holds its lock (and it is not brand new). When unsure: false.
bool temporary_owner_gone(const std::string& path);

// Whether a process of this host (same host tag) with this pid, started at or before
// `not_after` (seconds since the epoch), still runs.
bool process_runs(long pid, double not_after);

}  // namespace partet
