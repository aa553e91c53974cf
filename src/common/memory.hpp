// Memory figures of this process, its children and the machine, in MB (internal header): the
// one place they are read from the kernel.
#pragma once

namespace partet {

double current_rss_mb();        // this process now
double virtual_size_mb();       // this process's virtual size now (what RLIMIT_AS counts)
double own_peak_rss_mb();       // this process's peak so far
double children_peak_rss_mb();  // the largest waited-for child process's peak
// What the machine can still give without swapping (MemAvailable); 0 when unknown.
double available_memory_mb();

}  // namespace partet
