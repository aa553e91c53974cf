// Memory figures of this process, its children and the machine, in MB (internal header): the
// one place they are read from the kernel.
#pragma once
#include <string>

namespace partet {

double current_rss_mb();        // this process now
double virtual_size_mb();       // this process's virtual size now (what RLIMIT_AS counts)
// What this process may still map under its address-space limit (ulimit -v, a job's virtual
// memory limit): the limit less its virtual size, in MB; infinite without a limit.
double address_space_room_mb();
double own_peak_rss_mb();       // this process's peak so far
double children_peak_rss_mb();  // the largest waited-for child process's peak
// Makes every array of 1 MB or more go back to the system as soon as it is freed. glibc's
// default raises that threshold each time such an array is freed (up to 32 MB), after which
// arrays of that size come from the heap, whose freed space the process keeps: rank 0 frees each
// stage's arrays, and with the default its resident memory stayed near the sum of all stages'.
// The command calls this first; a program using the library keeps its own malloc settings.
void return_large_frees_to_system();

// What this process can still be given without swapping or being killed: the machine's
// MemAvailable, or less where its cgroup (a Slurm job's memory limit, a container's) allows less;
// 0 when unknown.
double available_memory_mb();

// What the cgroups of a process allow it still, in MB: over its cgroup and every ancestor with a
// memory limit, the least of limit - (usage - inactive page cache), since the kernel reclaims
// that cache before it kills. `self_cgroup` is /proc/self/cgroup's text; `root` the cgroup
// filesystem (/sys/fs/cgroup: cgroup v2 there, or v1's memory controller in root/memory).
// Negative when no cgroup limits the memory.
double cgroup_available_mb(const std::string& self_cgroup, const std::string& root);

}  // namespace partet
