#include "common/memory.hpp"

#include <malloc.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>

namespace partet {
namespace {

double peak_rss_mb(int who) {
  rusage usage{};
  getrusage(who, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

}  // namespace

double current_rss_mb() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return 0;
  long total = 0, resident = 0;
  const bool ok = std::fscanf(f, "%ld %ld", &total, &resident) == 2;
  std::fclose(f);
  return ok ? static_cast<double>(resident) * static_cast<double>(::sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0) : 0;
}

double virtual_size_mb() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return 0;
  long total = 0;
  const bool ok = std::fscanf(f, "%ld", &total) == 1;
  std::fclose(f);
  return ok ? static_cast<double>(total) * static_cast<double>(::sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0) : 0;
}

double address_space_room_mb() {
  rlimit limit{};
  if (::getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return HUGE_VAL;
  return static_cast<double>(limit.rlim_cur) / (1024.0 * 1024.0) - virtual_size_mb();
}

double own_peak_rss_mb() { return peak_rss_mb(RUSAGE_SELF); }
double children_peak_rss_mb() { return peak_rss_mb(RUSAGE_CHILDREN); }

namespace {

double machine_available_mb() {
  std::FILE* f = std::fopen("/proc/meminfo", "r");
  if (!f) return 0;
  char name[64];
  long long kb = 0;
  double available = 0;
  while (std::fscanf(f, "%63s %lld kB", name, &kb) == 2)
    if (std::strcmp(name, "MemAvailable:") == 0) available = static_cast<double>(kb) / 1024.0;
  std::fclose(f);
  return available;
}

// The first number in a file, or nothing (missing, "max", empty).
std::optional<double> number_in(const std::string& path) {
  std::ifstream in(path);
  double value = 0;
  if (in >> value) return value;
  return std::nullopt;
}

// A key's number in a memory.stat file; 0 when missing.
double stat_value(const std::string& path, const std::string& key) {
  std::ifstream in(path);
  std::string name;
  double value = 0;
  while (in >> name >> value)
    if (name == key) return value;
  return 0;
}

// A cgroup's memory files: v2's, or v1's memory controller's.
struct CgroupFiles {
  const char* limit;
  const char* usage;
  const char* inactive_cache;  // the key in memory.stat
};
constexpr CgroupFiles kV2{"memory.max", "memory.current", "inactive_file"};
constexpr CgroupFiles kV1{"memory.limit_in_bytes", "memory.usage_in_bytes", "total_inactive_file"};

// The least any level from `path` up to the root allows (negative: none limits).
double least_allowed_bytes(const std::string& mount, std::string path, const CgroupFiles& files) {
  constexpr double kNoLimit = 1e18;  // v1 writes "no limit" as about 2^63
  double least = -1;
  for (;;) {
    const std::string dir = mount + (path == "/" ? "" : path) + "/";
    const std::optional<double> limit = number_in(dir + files.limit);
    const std::optional<double> usage = number_in(dir + files.usage);
    if (limit && *limit < kNoLimit && usage) {
      const double used = std::max(0.0, *usage - stat_value(dir + "memory.stat", files.inactive_cache));
      const double allowed = std::max(0.0, *limit - used);
      if (least < 0 || allowed < least) least = allowed;
    }
    if (path.empty() || path == "/") return least;
    path.erase(path.find_last_of('/'));
    if (path.empty()) path = "/";
  }
}

}  // namespace

double cgroup_available_mb(const std::string& self_cgroup, const std::string& root) {
  std::istringstream lines(self_cgroup);
  std::string line;
  double least = -1;
  while (std::getline(lines, line)) {
    // "hierarchy-ID:controller-list:path"; v2's line is "0::path".
    const std::size_t first = line.find(':'), second = line.find(':', first + 1);
    if (first == std::string::npos || second == std::string::npos) continue;
    const std::string controllers = "," + line.substr(first + 1, second - first - 1) + ",";
    const std::string path = line.substr(second + 1);
    if (path.empty() || path[0] != '/') continue;
    double allowed = -1;
    if (controllers == ",,")
      allowed = least_allowed_bytes(root, path, kV2);
    else if (controllers.find(",memory,") != std::string::npos)
      allowed = least_allowed_bytes(root + "/memory", path, kV1);
    if (allowed >= 0 && (least < 0 || allowed < least)) least = allowed;
  }
  return least < 0 ? -1 : least / 1048576.0;
}

double available_memory_mb() {
  const double machine = machine_available_mb();
  std::ifstream in("/proc/self/cgroup");
  const std::string self_cgroup((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const double cgroup = cgroup_available_mb(self_cgroup, "/sys/fs/cgroup");
  if (cgroup < 0) return machine;
  return machine > 0 ? std::min(machine, cgroup) : cgroup;
}

void return_large_frees_to_system() { mallopt(M_MMAP_THRESHOLD, 1 << 20); }

}  // namespace partet
