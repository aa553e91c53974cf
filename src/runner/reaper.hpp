// The reaper: a small process, started with partet, that removes partet's temporaries when partet
// ends however it ends. A process cannot clean up after SIGKILL or the OOM killer, and Open MPI's
// mpirun, on Ctrl-C or SIGTERM, sends its ranks SIGKILL a millisecond or two after SIGTERM (after
// a second of SIGCONT alone): a loaded rank's interrupt thread loses that race. The reaper has
// its own session (a kill of the rank's process group misses it), ignores the interrupting
// signals, learns the files through a pipe, and acts when the pipe closes, i.e. when the process
// that started it has ended (internal header).
#pragma once
#include <string>

namespace partet::reaper {

// Starts the reaper. Call once, before any thread exists (the child must be single-threaded).
// Without one (it could not start, or never started), the functions below do nothing.
void start();
// The file at path is a temporary of this process: removed should the process end before forget.
void remember(const std::string& path);
void forget(const std::string& path);
// While holding, a process that ends leaves its files in place: a publish is under way, whose
// journal the next run completes from those files.
void hold(bool holding);
// In a forked child: close this process's end of the pipe, so that the reaper does not wait for
// the child too.
void close_in_child();

}  // namespace partet::reaper
