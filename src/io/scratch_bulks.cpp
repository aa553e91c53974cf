#include "io/scratch_bulks.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <vector>

#include "common/log.hpp"
#include "common/paths.hpp"
#include "common/test_hooks.hpp"
#include "io/file_owner.hpp"
#include "partet/errors.hpp"
#include "runner/interrupts.hpp"

namespace partet {
namespace {

constexpr char kFilePrefix[] = "partet-bulk-";
constexpr char kMagic[8] = {'p', 'a', 'r', 't', 'b', 'u', 'l', 'k'};

// Each bulk's header: the magic, then the length of each array.
struct Header {
  char magic[8];
  std::uint64_t steiner_points, tets, neighbours, rim;
};

template <class T>
std::size_t bytes_of(const std::vector<T>& v) {
  return v.size() * sizeof(T);
}

// Writes every byte at offset, which it moves on (false with errno set when it cannot).
bool write_at(int fd, const void* data, std::size_t size, std::uint64_t& offset) {
  const char* at = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::pwrite(fd, at, std::min<std::size_t>(size, std::size_t{1} << 30), static_cast<off_t>(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n == 0) errno = ENOSPC;
      return false;
    }
    at += n, size -= static_cast<std::size_t>(n), offset += static_cast<std::uint64_t>(n);
  }
  return true;
}

bool read_at(int fd, void* data, std::size_t size, std::uint64_t& offset) {
  char* at = static_cast<char*>(data);
  while (size > 0) {
    const ssize_t n = ::pread(fd, at, std::min<std::size_t>(size, std::size_t{1} << 30), static_cast<off_t>(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n == 0) errno = 0;  // shorter than its header says
      return false;
    }
    at += n, size -= static_cast<std::size_t>(n), offset += static_cast<std::uint64_t>(n);
  }
  return true;
}

template <class T>
bool read_array(int fd, std::vector<T>& v, std::uint64_t count, std::uint64_t& offset) {
  v.resize(count);
  return read_at(fd, v.data(), bytes_of(v), offset);
}

std::string reason(int error) { return error == 0 ? "it is shorter than it should be" : std::strerror(error); }

// A file in directory with a name for the shortest time (-1 with errno set when none can be made).
int nameless_file(const std::string& directory) {
  errno = EOPNOTSUPP;
  const int fd =
      test_hooks::nameless_files_refused() ? -1 : ::open(directory.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
  if (fd >= 0 || (errno != EOPNOTSUPP && errno != EISDIR && errno != EINVAL)) return fd;
  // No nameless files here (NFS, older filesystems): a name only until it is unlinked, remembered
  // meanwhile so that an interrupt or the reaper removes it (a kill between the two without a
  // reaper leaves it for the next run to remove).
  const std::string path = directory + "/" + kFilePrefix + "store" + temporary_suffix();
  int named = -1;
  if (!interrupts::create_remembered(path, [&] {
        named = ::open(path.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
        return named >= 0;
      }))
    return -1;
  ::unlink(path.c_str());
  interrupts::forget(path);
  return named;
}

}  // namespace

ScratchBulks::ScratchBulks(std::string directory) : directory_(std::move(directory)) {
  if (directory_.empty()) directory_ = ".";
}

ScratchBulks::~ScratchBulks() {
  if (fd_ >= 0) ::close(fd_);
}

void ScratchBulks::fail(const std::string& why) {
  failed_ = true;
  log::warning("cannot write the pieces' meshes to a scratch file in '" + directory_ + "' (" + why +
               "); they stay in memory for the rest of the run");
}

bool ScratchBulks::open_file() {
  if (fd_ >= 0) return true;
  fd_ = nameless_file(directory_);
  if (fd_ < 0) fail(std::strerror(errno));
  return fd_ >= 0;
}

// Gives a bulk's disk space back: a hole where the filesystem punches them, the whole file once
// nothing waits in it.
void ScratchBulks::release(const Slot& slot) {
  if (slots_.empty()) {
    if (::ftruncate(fd_, 0) == 0) end_ = 0;
    return;
  }
  (void)::fallocate(fd_, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, static_cast<off_t>(slot.offset),
                    static_cast<off_t>(slot.size));
}

bool ScratchBulks::put(int piece, const TetBlock& bulk) {
  if (bulk.numbered) throw InternalError("a numbered bulk was put in the scratch file (its ids would be lost)");
  if (failed_ || !open_file()) return false;
  drop(piece);
  Header header{{}, bulk.steiner_points.size(), bulk.tets.size(), bulk.neighbours.size(), bulk.rim.size()};
  std::memcpy(header.magic, kMagic, sizeof kMagic);
  std::uint64_t offset = end_;
  const bool ok = write_at(fd_, &header, sizeof header, offset) &&
                  write_at(fd_, bulk.steiner_points.data(), bytes_of(bulk.steiner_points), offset) &&
                  write_at(fd_, bulk.tets.data(), bytes_of(bulk.tets), offset) &&
                  write_at(fd_, bulk.neighbours.data(), bytes_of(bulk.neighbours), offset) &&
                  write_at(fd_, bulk.rim.data(), bytes_of(bulk.rim), offset);
  if (!ok) {
    const int error = errno;
    (void)!::ftruncate(fd_, static_cast<off_t>(end_));  // the part written goes back
    fail(std::strerror(error));
    return false;
  }
  slots_[piece] = {end_, offset - end_};
  end_ = offset;
  pieces_.insert(piece);
  stats_.bulks = static_cast<std::int64_t>(pieces_.size());
  stats_.bytes += static_cast<std::int64_t>(slots_[piece].size);
  return true;
}

void ScratchBulks::drop(int piece) {
  const auto it = slots_.find(piece);
  if (it == slots_.end()) return;
  const Slot slot = it->second;
  slots_.erase(it);
  release(slot);
}

TetBlock ScratchBulks::take(int piece) {
  const auto it = slots_.find(piece);
  if (it == slots_.end()) throw InternalError("piece " + std::to_string(piece) + " has no bulk in the scratch file");
  const Slot slot = it->second;
  TetBlock bulk;
  const std::string trouble = [&]() -> std::string {
    std::uint64_t offset = slot.offset;
    Header header{};
    if (!read_at(fd_, &header, sizeof header, offset)) return reason(errno);
    const std::uint64_t size = sizeof header + header.steiner_points * sizeof(Point3) +
                               (header.tets + header.neighbours) * sizeof(Tet) + header.rim * sizeof(std::uint64_t);
    if (std::memcmp(header.magic, kMagic, sizeof kMagic) != 0 || header.neighbours != header.tets || size != slot.size)
      return "it does not hold what partet wrote";
    if (!read_array(fd_, bulk.steiner_points, header.steiner_points, offset) ||
        !read_array(fd_, bulk.tets, header.tets, offset) ||
        !read_array(fd_, bulk.neighbours, header.neighbours, offset) || !read_array(fd_, bulk.rim, header.rim, offset))
      return reason(errno);
    return "";
  }();
  drop(piece);
  if (!trouble.empty())
    throw Error("cannot read piece " + std::to_string(piece) + "'s mesh back from the scratch file in '" + directory_ +
                "' (" + trouble + "); the disk under --scratch may be failing: give another directory");
  bulk.in = true;
  return bulk;
}

void check_scratch_directory(const std::string& directory) { check_writable_directory("--scratch", directory); }

}  // namespace partet

namespace partet {

void remove_stale_scratch(const std::string& directory) {
  DIR* dir = ::opendir(directory.c_str());
  if (!dir) return;
  std::vector<std::string> stale;
  while (const dirent* entry = ::readdir(dir)) {
    const std::string name = entry->d_name;
    long pid = 0;
    std::string host;
    if (name.rfind(kFilePrefix, 0) != 0 || !parse_temporary_suffix(name, pid, host) || host != host_tag()) continue;
    struct stat info {};
    const std::string path = directory + "/" + name;
    if (::stat(path.c_str(), &info) == 0 && !process_runs(pid, static_cast<double>(info.st_mtime)))
      stale.push_back(path);
  }
  ::closedir(dir);
  for (const std::string& path : stale) ::unlink(path.c_str());
}

}  // namespace partet
