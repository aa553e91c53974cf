// Memory figures of this process, its children and the machine, in MB (internal header): the
// one place they are read from the kernel.
#pragma once

namespace partet {

double current_rss_mb();        // this process now
double virtual_size_mb();       // this process's virtual size now (what RLIMIT_AS counts)
double own_peak_rss_mb();       // this process's peak so far
double children_peak_rss_mb();  // the largest waited-for child process's peak
// Makes every array of 1 MB or more go back to the system as soon as it is freed. glibc's
// default raises that threshold each time such an array is freed (up to 32 MB), after which
// arrays of that size come from the heap, whose freed space the process keeps: rank 0 frees each
// stage's arrays, and with the default its resident memory stayed near the sum of all stages'.
// The command calls this first; a program using the library keeps its own malloc settings.
void return_large_frees_to_system();

// What the machine can still give without swapping (MemAvailable); 0 when unknown.
double available_memory_mb();

}  // namespace partet
