#include "io/scratch_bulks.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include "common/log.hpp"
#include "io/file_owner.hpp"
#include "partet/errors.hpp"
#include "runner/interrupts.hpp"

namespace partet {
namespace {

constexpr char kFilePrefix[] = "partet-bulk-";
constexpr char kMagic[8] = {'p', 'a', 'r', 't', 'b', 'u', 'l', 'k'};

// The file's header: the magic, then the length of each array.
struct Header {
  char magic[8];
  std::uint64_t steiner_points, tets, neighbours, rim;
};

template <class T>
std::size_t bytes_of(const std::vector<T>& v) {
  return v.size() * sizeof(T);
}

// Writes every byte (false with errno set when it cannot).
bool write_all(int fd, const void* data, std::size_t size) {
  const char* at = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, at, std::min<std::size_t>(size, std::size_t{1} << 30));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n == 0) errno = ENOSPC;
      return false;
    }
    at += n, size -= static_cast<std::size_t>(n);
  }
  return true;
}

bool read_all(int fd, void* data, std::size_t size) {
  char* at = static_cast<char*>(data);
  while (size > 0) {
    const ssize_t n = ::read(fd, at, std::min<std::size_t>(size, std::size_t{1} << 30));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n == 0) errno = 0;  // shorter than its header says
      return false;
    }
    at += n, size -= static_cast<std::size_t>(n);
  }
  return true;
}

template <class T>
bool read_array(int fd, std::vector<T>& v, std::uint64_t count) {
  v.resize(count);
  return read_all(fd, v.data(), bytes_of(v));
}

std::string reason(int error) { return error == 0 ? "it is shorter than it should be" : std::strerror(error); }

}  // namespace

ScratchBulks::ScratchBulks(std::string directory) : directory_(std::move(directory)), suffix_(temporary_suffix()) {
  if (directory_.empty()) directory_ = ".";
}

ScratchBulks::~ScratchBulks() {
  for (const auto& [piece, path] : files_) remove(path);
}

void ScratchBulks::remove(const std::string& path) {
  ::unlink(path.c_str());
  interrupts::forget(path);
}

bool ScratchBulks::put(int piece, const TetBlock& bulk) {
  if (failed_) return false;
  if (auto old = files_.find(piece); old != files_.end()) remove(old->second), files_.erase(old);
  const std::string path =
      directory_ + "/" + kFilePrefix + std::to_string(piece) + "-" + std::to_string(written_++) + suffix_;
  int fd = -1;
  const bool made = interrupts::create_remembered(path, [&] {
    fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    return fd >= 0;
  });
  Header header{{}, bulk.steiner_points.size(), bulk.tets.size(), bulk.neighbours.size(), bulk.rim.size()};
  std::memcpy(header.magic, kMagic, sizeof kMagic);
  bool ok = made && write_all(fd, &header, sizeof header) &&
            write_all(fd, bulk.steiner_points.data(), bytes_of(bulk.steiner_points)) &&
            write_all(fd, bulk.tets.data(), bytes_of(bulk.tets)) &&
            write_all(fd, bulk.neighbours.data(), bytes_of(bulk.neighbours)) &&
            write_all(fd, bulk.rim.data(), bytes_of(bulk.rim));
  const int error = errno;
  if (fd >= 0 && ::close(fd) != 0 && ok) ok = false;
  if (!ok) {
    if (made) remove(path);
    failed_ = true;
    log::warning("cannot write the scratch file '" + path + "' (" + std::strerror(error) +
                 "); the pieces' meshes stay in memory for the rest of the run");
    return false;
  }
  files_[piece] = path;
  pieces_.insert(piece);
  stats_.bulks = static_cast<std::int64_t>(pieces_.size());
  stats_.bytes += static_cast<std::int64_t>(sizeof header + bytes_of(bulk.steiner_points) + bytes_of(bulk.tets) +
                                            bytes_of(bulk.neighbours) + bytes_of(bulk.rim));
  return true;
}

TetBlock ScratchBulks::take(int piece) {
  const auto it = files_.find(piece);
  if (it == files_.end()) throw InternalError("piece " + std::to_string(piece) + " has no bulk in the scratch files");
  const std::string path = it->second;
  files_.erase(it);
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  TetBlock bulk;
  const std::string trouble = [&]() -> std::string {
    Header header{};
    if (fd < 0 || !read_all(fd, &header, sizeof header)) return reason(errno);
    struct stat info {};
    const std::uint64_t size = sizeof header + header.steiner_points * sizeof(Point3) +
                               (header.tets + header.neighbours) * sizeof(Tet) + header.rim * sizeof(std::uint64_t);
    if (std::memcmp(header.magic, kMagic, sizeof kMagic) != 0 || header.neighbours != header.tets ||
        ::fstat(fd, &info) != 0 || static_cast<std::uint64_t>(info.st_size) != size)
      return "it is not the file partet wrote";
    if (!read_array(fd, bulk.steiner_points, header.steiner_points) || !read_array(fd, bulk.tets, header.tets) ||
        !read_array(fd, bulk.neighbours, header.neighbours) || !read_array(fd, bulk.rim, header.rim))
      return reason(errno);
    return "";
  }();
  if (fd >= 0) ::close(fd);
  remove(path);
  if (!trouble.empty())
    throw Error("the scratch file '" + path + "' holding piece " + std::to_string(piece) +
                "'s mesh was lost or changed during the run (" + trouble +
                "); give --scratch a directory nothing else cleans or writes to");
  bulk.in = true;
  return bulk;
}

void check_scratch_directory(const std::string& directory) {
  struct stat info {};
  if (::stat(directory.c_str(), &info) != 0 || !S_ISDIR(info.st_mode))
    throw OptionError("--scratch: '" + directory + "' is not a directory");
  if (::access(directory.c_str(), W_OK | X_OK) != 0)
    throw OptionError("--scratch: cannot write in '" + directory + "' (" + std::strerror(errno) + ")");
}

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
