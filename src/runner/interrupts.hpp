// What a signal that ends the run (Ctrl-C, a closed terminal, scancel, a time limit) does: one
// thread takes them all, so the cleanup is ordinary code. It removes this process's unpublished
// files, waits for a publish in progress to end (never leaving a half-published set), says which
// set of files is in place, and exits: 0 when the new set is complete, 128 + the signal's number
// when the previous files are (internal header).
#pragma once
#include <functional>
#include <string>

namespace partet::interrupts {

// The signals taken: SIGINT, SIGTERM, SIGHUP, SIGXCPU, SIGUSR1, SIGUSR2 (Slurm and Open MPI send
// the last two as warnings before a kill, whose default action ends the process). SIGPIPE is
// ignored, so a closed pipe fails a write instead of killing the run.
// Call at the start of main, before MPI_Init and before any other thread exists: threads started
// later inherit the blocked signals, so only the interrupt thread sees them. Starts the reaper.
void install();
// Whether install() ran in this process.
bool installed();

// In a forked child: the default action for every signal, none blocked (the child has no
// interrupt thread; it dies with its parent).
void reset_in_child();

// Files to remove when interrupted (this process's temporaries), and, through the reaper
// (reaper.hpp), when the process is killed outright: forget takes one off the list.
void forget(const std::string& path);
// Calls create() (which makes the file at path; false when it cannot) and remembers the file, as
// one step an interrupt cannot fall between: a file made while an interrupt removes the others
// would be left behind. Once an interrupt has begun, this waits for the process to end.
bool create_remembered(const std::string& path, const std::function<bool()>& create);

// What an interrupt says (without "partet: ") and how the run ends: `before` while the new
// output is not in place (exit 128 + the signal's number), `after` once it is (exit 0). "%s"
// becomes the signal's name. Empty: exit without a message (worker ranks).
void set_messages(const std::string& before, const std::string& after);
// The new output is in place (OutputSet::publish calls it with interrupts held off).
void mark_output_complete();

// While one exists, an interrupt waits: the files it protects move into place as a whole. An
// interrupt that has to wait says so at once, with `note` ("arrived while ..."), and ends the run
// as soon as the last one goes: this thread then waits for it (the run does not end on its own
// first, without the interrupt's message).
class Deferred {
 public:
  explicit Deferred(const std::string& note);
  ~Deferred();
  Deferred(const Deferred&) = delete;
  Deferred& operator=(const Deferred&) = delete;
};

// While one exists, this process's files stay in place should it be killed outright (the reaper,
// reaper.hpp, leaves them): a publish is under way, and its journal lets the next run complete it.
class KeptIfKilled {
 public:
  KeptIfKilled();
  ~KeptIfKilled();
  KeptIfKilled(const KeptIfKilled&) = delete;
  KeptIfKilled& operator=(const KeptIfKilled&) = delete;
};

// "SIGTERM" for 15, and so on.
std::string signal_name(int signal_number);

}  // namespace partet::interrupts
