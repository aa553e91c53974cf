#include "common/memory.hpp"

#include <malloc.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>

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

double own_peak_rss_mb() { return peak_rss_mb(RUSAGE_SELF); }
double children_peak_rss_mb() { return peak_rss_mb(RUSAGE_CHILDREN); }

double available_memory_mb() {
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

void return_large_frees_to_system() { mallopt(M_MMAP_THRESHOLD, 1 << 20); }

}  // namespace partet
