#include "common/paths.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "partet/errors.hpp"

namespace partet {

std::string absolute_path(const std::string& path) {
  if (!path.empty() && path[0] == '/') return path;
  char here[4096];
  return ::getcwd(here, sizeof here) ? std::string(here) + "/" + path : path;
}

std::string directory_of(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  return parent.empty() ? "." : parent.string();
}

void check_writable_directory(const std::string& option, const std::string& directory) {
  struct stat info {};
  if (::stat(directory.c_str(), &info) != 0 || !S_ISDIR(info.st_mode))
    throw OptionError(option + ": '" + directory + "' is not a directory");
  if (::access(directory.c_str(), W_OK | X_OK) != 0)
    throw OptionError(option + ": cannot write in '" + directory + "' (" + std::strerror(errno) + ")");
}

}  // namespace partet
