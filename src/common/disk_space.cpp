#include "common/disk_space.hpp"

#include <sys/statvfs.h>
#include <unistd.h>

namespace partet {

double free_disk_mb(const std::string& path) {
  struct statvfs fs {};
  if (statvfs(path.c_str(), &fs) != 0) return -1;
  // root may also write the blocks reserved for it
  const auto blocks = geteuid() == 0 ? fs.f_bfree : fs.f_bavail;
  return static_cast<double>(blocks) * static_cast<double>(fs.f_frsize) / 1048576.0;
}

}  // namespace partet
