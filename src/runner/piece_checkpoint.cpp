#include "runner/piece_checkpoint.hpp"

#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <vector>

#include "common/fnv1a.hpp"
#include "common/log.hpp"
#include "common/paths.hpp"
#include "common/write_all.hpp"
#include "io/file_owner.hpp"
#include "io/file_text.hpp"
#include "partet/errors.hpp"
#include "runner/serialize.hpp"

namespace partet {
namespace {

// The file's first bytes. The number changes with the form of the replies (serialize.cpp), so a
// file an older partet wrote is skipped rather than misread.
constexpr char kMagic[] = "partet piece checkpoint 1\n";
constexpr std::size_t kMagicSize = sizeof kMagic - 1;

std::string u64_bytes(std::uint64_t value) { return std::string(reinterpret_cast<const char*>(&value), 8); }

std::uint64_t u64_at(std::string_view bytes, std::size_t at) {
  std::uint64_t value = 0;
  std::memcpy(&value, bytes.data() + at, 8);
  return value;
}

bool write_all(int fd, std::string_view bytes) { return partet::write_all(fd, bytes.data(), bytes.size()); }

// One warning per process for files that cannot be written: the run goes on without them.
void warn_unwritable(const std::string& path, int error) {
  static bool warned = false;
  if (warned) return;
  warned = true;
  log::warning("cannot keep meshed pieces in the checkpoint ('" + path + "': " + std::strerror(error) +
               "); this run goes on, but a rerun will mesh them again");
}

}  // namespace

std::string PieceCheckpoint::key_of(const PieceSurface& piece, const TetgenOptions& tetgen) {
  return serialize_task(piece, tetgen);
}

std::string PieceCheckpoint::path_of(const std::string& key, int index) const {
  char name[64];
  std::snprintf(name, sizeof name, "piece-%d-%016llx.bin", index, static_cast<unsigned long long>(fnv1a(key)));
  return directory_ + "/" + name;
}

std::optional<std::string> PieceCheckpoint::find(const std::string& key, int index) const {
  const std::string path = path_of(key, index);
  std::error_code missing;
  if (!std::filesystem::exists(path, missing)) return std::nullopt;
  std::string file;
  try {
    file = file_text(path);
  } catch (const InputError& e) {
    log::warning(std::string(e.what()) + ": meshing piece " + std::to_string(index) + " again");
    return std::nullopt;
  }
  // magic, key size, key, reply size, reply, checksum of key and reply
  const std::string_view bytes(file);
  const std::size_t key_at = kMagicSize + 8;
  bool whole = bytes.size() >= key_at + 8 + 8 + 8 && bytes.substr(0, kMagicSize) == kMagic &&
               u64_at(bytes, kMagicSize) == key.size() && bytes.size() >= key_at + key.size() + 16;
  const std::size_t reply_at = key_at + key.size() + 8;
  const std::uint64_t reply_size = whole ? u64_at(bytes, reply_at - 8) : 0;
  whole = whole && bytes.size() == reply_at + reply_size + 8 &&
          u64_at(bytes, reply_at + reply_size) == fnv1a(bytes.substr(key_at, key.size() + 8 + reply_size));
  if (!whole) {
    log::warning("the checkpoint '" + path + "' is incomplete or damaged: meshing piece " + std::to_string(index) +
                 " again");
    return std::nullopt;
  }
  if (bytes.substr(key_at, key.size()) != key) return std::nullopt;  // another input with the same hash
  // The reply in place of the file's bytes: no second copy of a piece's mesh.
  std::string reply = std::move(file);
  reply.erase(reply_at + reply_size).erase(0, reply_at);
  if (!is_result_reply(reply)) return std::nullopt;
  set_reply_figures(reply, 0, 0);
  return reply;
}

void PieceCheckpoint::keep(const std::string& key, int index, const std::string& reply) const {
  if (!is_result_reply(reply)) return;
  const std::string path = path_of(key, index), temporary = path + temporary_suffix();
  if (::mkdir(directory_.c_str(), 0777) != 0 && errno != EEXIST) return warn_unwritable(directory_, errno);
  // Locked while it is written, so a run starting on another node never takes it for a dead
  // run's leftover (temporary_owner_gone), however long the write takes.
  OwnedFile file;
  if (!file.create(temporary)) return warn_unwritable(temporary, errno);
  const int fd = file.fd();
  const std::string head = kMagic + u64_bytes(key.size());
  const std::string reply_size = u64_bytes(reply.size());
  const std::uint64_t sum = fnv1a(reply, fnv1a(reply_size, fnv1a(key)));
  const bool written = write_all(fd, head) && write_all(fd, key) && write_all(fd, reply_size) && write_all(fd, reply) &&
                       write_all(fd, u64_bytes(sum)) && ::fsync(fd) == 0;
  const int error = errno;
  if (!written || ::rename(temporary.c_str(), path.c_str()) != 0) {
    const int cause = written ? errno : error;
    ::unlink(temporary.c_str());
    return warn_unwritable(path, cause);
  }
}

void check_checkpoint_directory(const std::string& directory) {
  if (::mkdir(directory.c_str(), 0777) != 0 && errno != EEXIST)
    throw OptionError("--checkpoint: cannot make '" + directory + "' (" + std::strerror(errno) + ")");
  check_writable_directory("--checkpoint", directory);
  // What killed runs were writing when they ended.
  if (DIR* dir = ::opendir(directory.c_str())) {
    std::vector<std::string> stale;
    while (const dirent* entry = ::readdir(dir)) {
      const std::string name = entry->d_name, path = directory + "/" + name;
      long pid = 0;
      std::string host;
      if (name.rfind("piece-", 0) == 0 && parse_temporary_suffix(name, pid, host) && temporary_owner_gone(path))
        stale.push_back(path);
    }
    ::closedir(dir);
    for (const std::string& path : stale) ::unlink(path.c_str());
  }
}

}  // namespace partet
