#include "common/disk_space.hpp"

#include <sys/statvfs.h>
#include <unistd.h>

namespace partet {

DiskRoom disk_room(const std::string& path) {
  struct statvfs fs {};
  if (statvfs(path.c_str(), &fs) != 0) return {};
  // root may also write the blocks reserved for it
  const bool root = geteuid() == 0;
  const auto free_blocks = root ? fs.f_bfree : fs.f_bavail;
  const auto reserved = fs.f_bfree - fs.f_bavail;
  const auto all_blocks = root || fs.f_blocks < reserved ? fs.f_blocks : fs.f_blocks - reserved;
  const double block_mb = static_cast<double>(fs.f_frsize) / 1048576.0;
  return {static_cast<double>(free_blocks) * block_mb, static_cast<double>(all_blocks) * block_mb};
}

}  // namespace partet
