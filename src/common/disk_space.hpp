// Free room on a filesystem (internal header).
#pragma once
#include <string>

namespace partet {

// What this process may still write on the filesystem holding `path` (a file or a directory), in MB (statvfs: the
// blocks reserved for root count for root only; a user's quota does not show); negative when
// unknown.
double free_disk_mb(const std::string& path);

}  // namespace partet
