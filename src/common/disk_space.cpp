#include "common/disk_space.hpp"

#include <sys/statvfs.h>
#include <unistd.h>

namespace partet {

double free_disk_mb(const std::string& directory) {
  struct statvfs fs {};
  if (statvfs(directory.c_str(), &fs) != 0) return -1;
  // root may also write the blocks reserved for it
  const auto blocks = geteuid() == 0 ? fs.f_bfree : fs.f_bavail;
  return static_cast<double>(blocks) * static_cast<double>(fs.f_frsize) / 1048576.0;
}

std::string directory_of(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

}  // namespace partet
