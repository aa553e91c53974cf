#include "runner/interrupts.hpp"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <set>
#include <thread>

#include "common/test_hooks.hpp"
#include "runner/reaper.hpp"

namespace partet::interrupts {
namespace {

constexpr int kTaken[] = {SIGINT, SIGTERM, SIGHUP, SIGXCPU, SIGUSR1, SIGUSR2};

// Never destroyed: the interrupt thread may run while static objects are destroyed at exit.
struct State {
  std::recursive_mutex mutex;  // held by Deferred sections and by the interrupt's cleanup
  std::set<std::string> files;
  std::string before, after;
  bool output_complete = false;
  bool installed = false;
  std::atomic<int> deferring{0};  // Deferred sections open
  std::atomic<bool> ending{false};  // an interrupt has begun (it may wait for a Deferred section)
  std::string while_deferred;     // said when an interrupt has to wait for one
};
State& state() {
  static State* s = new State;
  return *s;
}

sigset_t taken_set() {
  sigset_t set;
  sigemptyset(&set);
  for (int s : kTaken) sigaddset(&set, s);
  return set;
}

[[noreturn]] void end_run(int signal_number) {
  test_hooks::interrupt_cleanup();
  State& s = state();
  s.ending = true;
  if (s.deferring > 0 && !s.while_deferred.empty()) {
    std::string text = "partet: " + signal_name(signal_number) + " " + s.while_deferred + "\n";
    (void)!::write(STDERR_FILENO, text.data(), text.size());
  }
  std::lock_guard<std::recursive_mutex> lock(s.mutex);  // a publish in progress ends first
  for (const std::string& f : s.files) ::unlink(f.c_str());
  if (const std::string& message = s.output_complete ? s.after : s.before; !message.empty()) {
    std::string text = message;
    if (const auto at = text.find("%s"); at != std::string::npos) text.replace(at, 2, signal_name(signal_number));
    text = "partet: " + text + "\n";
    (void)!::write(STDERR_FILENO, text.data(), text.size());
  }
  ::_exit(s.output_complete ? 0 : 128 + signal_number);
}

void wait_for_signals() {
  const sigset_t set = taken_set();
  for (;;) {
    int signal_number = 0;
    if (::sigwait(&set, &signal_number) == 0) end_run(signal_number);
  }
}

}  // namespace

void install() {
  State& s = state();
  if (s.installed) return;
  reaper::start();  // (before the interrupt thread: its fork must copy a single thread)
  ::signal(SIGPIPE, SIG_IGN);
  const sigset_t set = taken_set();
  ::pthread_sigmask(SIG_BLOCK, &set, nullptr);
  std::thread(wait_for_signals).detach();
  s.installed = true;
}

bool installed() { return state().installed; }

void reset_in_child() {
  for (int s : kTaken) ::signal(s, SIG_DFL);
  for (int s : {SIGPIPE, SIGABRT, SIGSEGV, SIGBUS}) ::signal(s, SIG_DFL);
  sigset_t none;
  sigemptyset(&none);
  ::pthread_sigmask(SIG_SETMASK, &none, nullptr);
  reaper::close_in_child();
}

bool create_remembered(const std::string& path, const std::function<bool()>& create) {
  State& s = state();
  std::lock_guard<std::recursive_mutex> lock(s.mutex);  // end_run holds it from its first unlink to the exit
  if (!create()) return false;
  s.files.insert(path);
  reaper::remember(path);
  return true;
}

void forget(const std::string& path) {
  State& s = state();
  std::lock_guard<std::recursive_mutex> lock(s.mutex);
  s.files.erase(path);
  reaper::forget(path);
}

KeptIfKilled::KeptIfKilled() { reaper::hold(true); }
KeptIfKilled::~KeptIfKilled() { reaper::hold(false); }

void set_messages(const std::string& before, const std::string& after) {
  State& s = state();
  std::lock_guard<std::recursive_mutex> lock(s.mutex);
  s.before = before;
  s.after = after;
}

void mark_output_complete() {
  State& s = state();
  std::lock_guard<std::recursive_mutex> lock(s.mutex);
  s.output_complete = true;
}

Deferred::Deferred(const std::string& note) {
  State& s = state();
  s.mutex.lock();
  s.while_deferred = note;
  ++s.deferring;
}
Deferred::~Deferred() {
  State& s = state();
  const bool last = --s.deferring == 0;
  s.mutex.unlock();
  if (!last || !s.ending) return;
  for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));  // the interrupt ends the run now
}

std::string signal_name(int signal_number) {
  switch (signal_number) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    case SIGXCPU: return "SIGXCPU";
    case SIGUSR1: return "SIGUSR1";
    case SIGUSR2: return "SIGUSR2";
    default: return "signal " + std::to_string(signal_number);
  }
}

}  // namespace partet::interrupts
