#include "common/paths.hpp"

#include <unistd.h>

namespace partet {

std::string absolute_path(const std::string& path) {
  if (!path.empty() && path[0] == '/') return path;
  char here[4096];
  return ::getcwd(here, sizeof here) ? std::string(here) + "/" + path : path;
}

}  // namespace partet
