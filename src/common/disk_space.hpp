// Free room on a filesystem (internal header).
#pragma once
#include <string>

namespace partet {

// The room on the filesystem holding `path` (a file or a directory), in MB, from statvfs (the blocks
// reserved for root count for root only; a user's quota does not show); negative when unknown.
struct DiskRoom {
  double free_mb = -1;      // what this process may still write there
  double capacity_mb = -1;  // what it could write there were every file removed: the most room that can be made
};
DiskRoom disk_room(const std::string& path);
inline double free_disk_mb(const std::string& path) { return disk_room(path).free_mb; }

}  // namespace partet
