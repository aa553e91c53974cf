#include "io/output_set.hpp"

#include "io/buffered_file.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include "io/file_owner.hpp"
#include "partet/errors.hpp"
#include "common/log.hpp"
#include "common/paths.hpp"
#include "runner/interrupts.hpp"
#include "common/test_hooks.hpp"
#include "common/write_all.hpp"

namespace partet {
namespace {

namespace fs = std::filesystem;

constexpr const char* kJournalHeader = "partet publish journal 1";
constexpr const char* kOld = ".old";  // a previous file set aside: FINAL.old<suffix>

std::string absolute(const std::string& path) {
  std::error_code ec;
  const fs::path a = fs::absolute(path, ec);
  return ec ? path : a.lexically_normal().string();
}

bool exists_here(const std::string& path) {  // the name itself, a symbolic link included
  struct stat st {};
  return ::lstat(path.c_str(), &st) == 0;
}

bool same_file(int fd, const std::string& path) {
  struct stat a {}, b {};
  return ::fstat(fd, &a) == 0 && ::stat(path.c_str(), &b) == 0 && a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}

// Which file a name stands for, as it was written: "device inode size mtime-ns" (empty when there
// is none). Size and time because a file removed and another made under its name often get the
// same inode number back.
std::string identity(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) return "";
  return std::to_string(st.st_dev) + " " + std::to_string(st.st_ino) + " " + std::to_string(st.st_size) + " " +
         std::to_string(st.st_mtim.tv_sec * 1000000000LL + st.st_mtim.tv_nsec);
}

// Whether `path` is the file a journal recorded (older journals record only "device inode").
bool is_recorded(const std::string& path, const std::string& recorded) {
  if (recorded.empty()) return false;
  const std::string now = identity(path);
  return now == recorded || (std::count(recorded.begin(), recorded.end(), ' ') == 1 && now.rfind(recorded + " ", 0) == 0);
}

void sync_directory(const std::string& directory) {
  const int fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);  // best effort: some filesystems refuse to sync a directory
  ::close(fd);
}

[[noreturn]] void refuse(const std::string& path, const std::string& why) {
  throw OutputError("cannot write '" + path + "': " + why);
}

void publish_step(int& step) { test_hooks::publish_step(++step); }

// What a journal records: every move of one publish.
struct Journal {
  long pid = 0;
  std::string host;
  std::string suffix;
  std::vector<std::string> files;       // final paths (absolute); each came from FINAL<suffix>
  std::vector<std::string> superseded;  // previous files the set removes (absolute)
  std::vector<std::string> made;        // per file: its new file's identity (not in older journals)
  bool complete = false;                // the journal was written to its end

  std::string old_copy(const std::string& path) const { return path + kOld + suffix; }
  std::string temporary(const std::string& path) const { return path + suffix; }

  std::string text() const {
    std::ostringstream out;
    out << kJournalHeader << "\n"
        << "# A partet run was moving these files into place when it was stopped; the next partet\n"
        << "# command on this prefix (mesh, check or info) completes the move.\n"
        << "owner " << pid << " " << host << "\n"
        << "suffix " << suffix << "\n";
    for (std::size_t i = 0; i < files.size(); ++i) {
      out << "file " << files[i] << "\n";
      if (i < made.size()) out << "made " << made[i] << "\n";
    }
    for (const std::string& f : superseded) out << "remove " << f << "\n";
    out << "end\n";
    return out.str();
  }

  static Journal read(int fd) {
    Journal j;
    std::string text;
    char buffer[4096];
    ssize_t n;
    ::lseek(fd, 0, SEEK_SET);
    while ((n = ::read(fd, buffer, sizeof buffer)) > 0) text.append(buffer, static_cast<std::size_t>(n));
    std::istringstream in(text);
    std::string line;
    if (!std::getline(in, line) || line != kJournalHeader) return j;
    while (std::getline(in, line)) {
      const auto space = line.find(' ');
      const std::string key = line.substr(0, space), value = space == std::string::npos ? "" : line.substr(space + 1);
      if (key == "owner") {
        std::istringstream owner(value);
        owner >> j.pid >> j.host;
      } else if (key == "suffix") {
        j.suffix = value;
      } else if (key == "file") {
        j.files.push_back(value);
      } else if (key == "made") {
        j.made.push_back(value);
      } else if (key == "remove") {
        j.superseded.push_back(value);
      } else if (key == "end") {
        j.complete = !j.suffix.empty();
      }
    }
    return j;
  }
};

void write_journal(int fd, const Journal& journal, const std::string& path) {
  const std::string text = journal.text();
  if (!write_all(fd, text.data(), text.size())) refuse(path, std::strerror(errno));
  if (::fsync(fd) != 0 && errno != EINVAL) refuse(path, std::strerror(errno));
  sync_directory(directory_of(path));
}

// Whether new file i of a journal is in place: its temporary's identity is at its final name.
bool moved_in(const Journal& j, std::size_t i) {
  return i < j.made.size() && is_recorded(j.files[i], j.made[i]);
}

// Whether new file i of a journal still waits under its temporary name: the file written there,
// not another one put there since (older journals, without identities: any file there).
bool waiting(const Journal& j, std::size_t i) {
  const std::string temporary = j.temporary(j.files[i]);
  if (i < j.made.size() && !j.made[i].empty()) return is_recorded(temporary, j.made[i]);
  return exists_here(temporary);
}

// The new file of a journal that is neither waiting under its temporary name nor in place: removed
// or replaced by something else meanwhile (empty: none is, or the journal does not say).
std::string lost_file(const Journal& j) {
  if (j.made.size() != j.files.size()) return "";
  for (std::size_t i = 0; i < j.files.size(); ++i)
    if (!waiting(j, i) && !moved_in(j, i)) return j.files[i];
  return "";
}

// Undoes a journal's moves that happened: each previous file back under its name (from its second
// name), the new files gone. For a set whose new files cannot all be put in place.
std::string restore_previous(const Journal& j, const std::string& journal_path, const std::string& lost) {
  for (std::size_t i = 0; i < j.files.size(); ++i) {
    const std::string& f = j.files[i];
    const std::string old = j.old_copy(f);
    if (exists_here(old)) {
      if (identity(old) == identity(f))
        ::unlink(old.c_str());  // still in place: only the second name goes
      else
        std::rename(old.c_str(), f.c_str());
    } else if (moved_in(j, i)) {
      ::unlink(f.c_str());  // the set had no file there before
    }
    ::unlink(j.temporary(f).c_str());
  }
  for (const std::string& f : j.superseded)
    if (exists_here(j.old_copy(f))) std::rename(j.old_copy(f).c_str(), f.c_str());
  for (const std::string& f : j.files) sync_directory(directory_of(f));
  return "could not complete the publish that a stopped partet run (pid " + std::to_string(j.pid) +
         ") left half done: the new file for '" + lost +
         "' was removed or replaced meanwhile; the previous files are back in place (journal '" + journal_path + "')";
}

// Finishes the moves a complete journal lists: the new files were all written and synced before
// it was, so the new set is the one to complete, unless one of them was removed since (then the
// previous set is put back).
std::string complete_moves(const Journal& j, const std::string& journal_path) {
  if (const std::string lost = lost_file(j); !lost.empty()) return restore_previous(j, journal_path, lost);
  for (std::size_t i = 0; i < j.files.size(); ++i) {
    const std::string& f = j.files[i];
    const std::string temporary = j.temporary(f);
    if (!waiting(j, i)) {
      ::unlink(temporary.c_str());  // a file put under the run's temporary name after its own moved in
      continue;
    }
    if (std::rename(temporary.c_str(), f.c_str()) != 0)
      throw OutputError("cannot complete the interrupted publish listed in '" + journal_path + "': moving '" +
                        temporary + "' to '" + f + "': " + std::strerror(errno));
  }
  for (const std::string& f : j.files) ::unlink(j.old_copy(f).c_str());
  for (const std::string& f : j.superseded) {
    ::unlink(j.old_copy(f).c_str());
    ::unlink(f.c_str());  // not yet set aside when the run stopped: it belongs to the previous set
  }
  for (const std::string& f : j.files) sync_directory(directory_of(f));
  return "completed the publish of " + std::to_string(j.files.size()) + " file(s) that a stopped partet run (pid " +
         std::to_string(j.pid) + ") left half done (journal '" + journal_path + "')";
}

struct FileDescriptor {
  int fd;
  explicit FileDescriptor(int f) : fd(f) {}
  ~FileDescriptor() {
    if (fd >= 0) ::close(fd);
  }
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
};

double age_seconds(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return 0;
  return static_cast<double>(std::time(nullptr) - st.st_mtime);
}

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Holds the journal of a prefix: while it exists and its owner lives, no other run publishes
// there. A journal whose owner is gone is completed (and removed) before it is taken.
class JournalLock {
 public:
  JournalLock(std::string path, double wait_seconds) : path_(std::move(path)) {
    const double deadline = now() + wait_seconds;
    bool said = false;
    for (Take t; (t = try_take()) != Take::taken;) {
      if (t == Take::again) continue;
      if (now() > deadline)
        throw OutputError("gave up after " + std::to_string(static_cast<int>(wait_seconds)) + " s waiting for " +
                          holder_ + " to finish publishing there (it holds '" + path_ +
                          "'); once it no longer runs, the next partet command on this prefix completes its publish");
      if (!said) log::warning("waiting for " + holder_ + " to finish publishing at the same prefix ('" + path_ + "')");
      said = true;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  ~JournalLock() { release(); }
  JournalLock(const JournalLock&) = delete;
  JournalLock& operator=(const JournalLock&) = delete;

  int fd() const { return file_.fd(); }
  const std::string& path() const { return path_; }
  // What completing a dead run's journal did (empty: there was none).
  const std::string& recovered() const { return recovered_; }
  void release() {
    if (file_.fd() >= 0) ::unlink(path_.c_str());
    file_.close();
  }

 private:
  enum class Take { taken, again, busy };
  // Takes the journal, or completes a dead owner's (then: again); busy while a live run holds it.
  Take try_take() {
    if (file_.create(path_)) {
      // A run examining a journal that appeared this instant holds it briefly; then it is ours.
      LockTry lock = file_.lock();
      for (int i = 0; i < 50 && lock == LockTry::held_elsewhere; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        lock = try_lock(file_.fd());
      }
      if (lock != LockTry::held_elsewhere && same_file(file_.fd(), path_)) return Take::taken;
      file_.close();
      return Take::busy;
    }
    if (errno != EEXIST) refuse(path_, std::strerror(errno));
    const FileDescriptor held(::open(path_.c_str(), O_RDWR | O_CLOEXEC));
    const int fd = held.fd;
    if (fd < 0) {
      if (errno == ENOENT) return Take::again;  // removed meanwhile
      refuse(path_, std::strerror(errno));
    }
    const Journal journal = Journal::read(fd);
    // An owner between taking the journal and writing it (or stopped there) has not named itself.
    holder_ = journal.pid <= 0 ? "another partet run (its journal not yet written)"
                               : "another partet run (pid " + std::to_string(journal.pid) +
                                     (journal.host == host_tag() ? " on this host)" : ", host " + journal.host + ")");
    const LockTry lock = try_lock(fd);
    const bool owner_gone =
        lock == LockTry::acquired ||
        (lock == LockTry::unsupported && journal.host == host_tag() && !process_runs(journal.pid, now_epoch()));
    Take next = Take::busy;
    if (owner_gone && same_file(fd, path_)) {
      if (journal.complete) {
        recovered_ = complete_moves(journal, path_);
        ::unlink(path_.c_str());
        next = Take::again;
      } else if (age_seconds(path_) > 10) {
        ::unlink(path_.c_str());  // its run stopped before listing a single move: nothing to complete
        next = Take::again;
      }
    }
    return next;
  }

  static double now_epoch() { return static_cast<double>(std::time(nullptr)); }

  std::string path_;
  OwnedFile file_;
  std::string holder_ = "another partet run";
  std::string recovered_;
};

// The previous files at `directory` that `belongs` claims and the new set does not write.
std::vector<std::string> superseded_files(const std::string& directory,
                                          const std::function<bool(const std::string&)>& belongs,
                                          const std::set<std::string>& finals) {
  std::vector<std::string> found;
  DIR* dir = ::opendir(directory.c_str());
  if (!dir) return found;
  while (const dirent* entry = ::readdir(dir)) {
    const std::string name = entry->d_name, path = absolute(directory + "/" + name);
    if (belongs(name) && finals.count(path) == 0) found.push_back(path);
  }
  ::closedir(dir);
  return found;
}

}  // namespace

struct OutputSet::Impl {
  std::string journal;
  std::string suffix = temporary_suffix();
  std::vector<std::string> temporaries;
  std::vector<OwnedFile> owned;  // locked while this run lives
  struct Family {
    std::string directory;
    std::function<bool(const std::string&)> belongs;
  };
  std::vector<Family> families;
  bool published = false;
};

std::string journal_path(const std::string& prefix) { return prefix + ".partet-publish"; }

std::size_t OutputSet::longest_extra_name(const std::string& final_path) {
  // FINAL.old.tmp-<pid up to 10 digits>-<8 hex>-<8 hex>
  return fs::path(final_path).filename().string().size() + std::strlen(kOld) + 5 + 10 + 1 + 8 + 1 + 8;
}

OutputSet::OutputSet(std::string journal) : impl_(std::make_unique<Impl>()) {
  impl_->journal = absolute(journal);
}

OutputSet::~OutputSet() {
  if (!impl_->published) discard();
}

void OutputSet::add(const std::string& final_path, const std::function<void(const std::string&)>& write_file) {
  const std::string temporary = final_path + impl_->suffix;
  OwnedFile owned;
  if (!interrupts::create_remembered(temporary, [&] { return owned.create(temporary); })) {
    const std::string reason = std::strerror(errno);
    discard();
    refuse(final_path, reason);
  }
  finals_.push_back(final_path);
  impl_->temporaries.push_back(temporary);
  impl_->owned.push_back(std::move(owned));
  try {
    write_file(temporary);
  } catch (...) {
    discard();
    throw;
  }
}

const std::string& OutputSet::temporary_name_suffix() const { return impl_->suffix; }

void OutputSet::supersede(const std::string& directory, std::function<bool(const std::string&)> belongs) {
  impl_->families.push_back({directory, std::move(belongs)});
}

void OutputSet::finish_writes() {
  try {
    finish_background_writes();
  } catch (...) {
    discard();
    throw;
  }
}

void OutputSet::discard() {
  abandon_background_writes();  // before the files go
  for (const std::string& t : impl_->temporaries) {
    std::remove(t.c_str());
    interrupts::forget(t);
  }
  impl_->temporaries.clear();
  impl_->owned.clear();
  impl_->families.clear();  // (a set written again names them again)
  finals_.clear();
}

void OutputSet::publish() {
  finish_writes();
  if (finals_.empty()) return;
  test_hooks::before_publish();
  // The new files reach the disk before the journal names them (a power cut must not leave a
  // journal pointing at files that were never written).
  for (const OwnedFile& f : impl_->owned)
    if (::fsync(f.fd()) != 0 && errno != EINVAL) {
      const std::string reason = std::strerror(errno), failed = finals_.front();
      discard();
      refuse(failed, reason);
    }
  std::unique_ptr<JournalLock> lock;
  Journal journal;
  std::optional<interrupts::KeptIfKilled> kept_if_killed;  // from the journal on: it needs the files
  // From the journal on, the moves end as a whole: an interrupt waits for them. (Taken before the
  // journal is written: an interrupt between the two would remove the files a journal names, and
  // completing that journal would then remove the previous set's files that the new one supersedes.)
  std::optional<interrupts::Deferred> hold_interrupts;
  try {
    lock = std::make_unique<JournalLock>(impl_->journal, test_hooks::publish_wait_seconds(lock_wait_seconds));
    if (!lock->recovered().empty()) log::warning(lock->recovered());
    journal.pid = static_cast<long>(::getpid());
    journal.host = host_tag();
    journal.suffix = impl_->suffix;
    std::set<std::string> finals;
    for (const std::string& f : finals_) journal.files.push_back(absolute(f)), finals.insert(journal.files.back());
    for (const std::string& t : impl_->temporaries) journal.made.push_back(identity(t));
    for (const Impl::Family& family : impl_->families)
      for (const std::string& f : superseded_files(family.directory, family.belongs, finals))
        journal.superseded.push_back(f);
    kept_if_killed.emplace();
    hold_interrupts.emplace(
        "arrived while the new files move into place: finishing that first (if this process is killed meanwhile, the "
        "next partet command on this prefix completes it)");
    write_journal(lock->fd(), journal, lock->path());
    test_hooks::publish_step(0);  // the journal is written, no file has moved
  } catch (...) {
    discard();
    throw;
  }

  int step = 0;
  publish_step(step);  // 1: the journal lists every move
  const std::size_t n = finals_.size();
  enum class Aside { none, linked, renamed };
  std::vector<Aside> aside(n, Aside::none);
  std::vector<char> moved_in(n, 0), superseded_aside(journal.superseded.size(), 0);
  auto undo = [&] {
    for (std::size_t i = 0; i < n; ++i) {
      const std::string& f = journal.files[i];
      if (aside[i] == Aside::renamed || (aside[i] == Aside::linked && moved_in[i]))
        std::rename(journal.old_copy(f).c_str(), f.c_str());  // back in its place, over the new file
      else if (aside[i] == Aside::linked)
        ::unlink(journal.old_copy(f).c_str());  // still in place: only the second name goes
      else if (moved_in[i])
        ::unlink(f.c_str());
    }
    for (std::size_t i = 0; i < superseded_aside.size(); ++i)
      if (superseded_aside[i])
        std::rename(journal.old_copy(journal.superseded[i]).c_str(), journal.superseded[i].c_str());
    discard();
    lock->release();
  };
  auto fail = [&](std::string path, const std::string& why) {  // a copy: undo() clears finals_
    undo();
    refuse(path, why + " (the previous files are left as they were)");
  };
  // 1. The previous files stay reachable under a second name (where they exist).
  for (std::size_t i = 0; i < n; ++i) {
    const std::string& f = journal.files[i];
    if (!exists_here(f)) continue;
    publish_step(step);
    struct stat st {};
    if (::lstat(f.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) fail(finals_[i], "it exists and is not a regular file");
    if (::link(f.c_str(), journal.old_copy(f).c_str()) == 0) {
      aside[i] = Aside::linked;
    } else if (std::rename(f.c_str(), journal.old_copy(f).c_str()) == 0) {  // no hard links here
      aside[i] = Aside::renamed;
    } else {
      fail(finals_[i], std::strerror(errno));
    }
  }
  for (std::size_t i = 0; i < journal.superseded.size(); ++i) {
    publish_step(step);
    if (std::rename(journal.superseded[i].c_str(), journal.old_copy(journal.superseded[i]).c_str()) != 0)
      fail(journal.superseded[i], std::strerror(errno));
    superseded_aside[i] = 1;
  }
  // 2. The new files move in (each rename replaces a previous file at once).
  const int inject = test_hooks::publish_failure();
  for (std::size_t i = 0; i < n; ++i) {
    publish_step(step);
    if (static_cast<int>(i) + 1 == inject) errno = EIO;
    if (static_cast<int>(i) + 1 == inject || std::rename(impl_->temporaries[i].c_str(), journal.files[i].c_str()) != 0)
      fail(finals_[i], std::strerror(errno));
    moved_in[i] = 1;
  }
  std::set<std::string> directories;
  for (const std::string& f : journal.files) directories.insert(directory_of(f));
  for (const std::string& d : directories) sync_directory(d);
  interrupts::mark_output_complete();
  impl_->published = true;
  for (const std::string& t : impl_->temporaries) interrupts::forget(t);
  impl_->temporaries.clear();
  impl_->owned.clear();
  // 3. The previous set goes, then the journal.
  publish_step(step);
  for (std::size_t i = 0; i < n; ++i)
    if (aside[i] != Aside::none) ::unlink(journal.old_copy(journal.files[i]).c_str());
  for (const std::string& f : journal.superseded) ::unlink(journal.old_copy(f).c_str());
  lock->release();
}

std::string settle_publish(const std::string& prefix, double wait_seconds) {
  const std::string journal = absolute(journal_path(prefix));
  if (!exists_here(journal)) return "";
  JournalLock lock(journal, test_hooks::publish_wait_seconds(wait_seconds));
  return lock.recovered();
}

void check_output_paths(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs) {
  // Asked for by the command line, and impossible: a usage error, before any work.
  auto refuse = [](const std::string& path, const std::string& why) {
    throw OptionError("cannot write '" + path + "': " + why);
  };
  std::vector<std::pair<std::string, std::string>> seen;  // (normalized path, as given)
  auto normalized = [](const std::string& p) {
    std::error_code ec;
    const fs::path n = fs::weakly_canonical(fs::absolute(p, ec), ec);
    return ec ? p : n.string();
  };
  for (const std::string& p : inputs) seen.push_back({normalized(p), p});
  for (const std::string& p : outputs) {
    if (p.empty()) throw OptionError("an output path is empty");
    if (p.find('\n') != std::string::npos) refuse(p, "the path contains a line break");
    if (p.back() == '/' || fs::is_directory(p)) refuse(p, "it is a directory (give a file name)");
    std::error_code ec;
    const fs::file_status link_status = fs::symlink_status(p, ec);
    if (fs::is_symlink(link_status))
      refuse(p, "it is a symbolic link (to '" + fs::read_symlink(p, ec).string() +
                    "'); partet replaces files by renaming, which would replace the link: give the target's path");
    if (fs::exists(link_status) && !fs::is_regular_file(link_status)) refuse(p, "it exists and is not a regular file");
    const std::string directory = directory_of(p);
    if (!fs::is_directory(directory, ec)) refuse(p, "directory '" + directory + "' does not exist");
    if (::access(directory.c_str(), W_OK | X_OK) != 0) refuse(p, "directory '" + directory + "' is not writable");
    const long name_max = ::pathconf(directory.c_str(), _PC_NAME_MAX);
    const std::size_t limit = name_max > 0 ? static_cast<std::size_t>(name_max) : NAME_MAX;
    if (OutputSet::longest_extra_name(p) > limit)
      refuse(p, "its name is too long for the filesystem once partet's temporary suffix is added (names up to " +
                    std::to_string(limit - (OutputSet::longest_extra_name(p) - fs::path(p).filename().string().size())) +
                    " characters work here)");
    if (absolute(p).size() + (OutputSet::longest_extra_name(p) - fs::path(p).filename().string().size()) >= PATH_MAX)
      refuse(p, "the path is too long");
    const std::string n = normalized(p);
    for (const auto& [other, given] : seen)
      if (other == n) refuse(p, "it is the same file as '" + given + "'");
    seen.push_back({n, p});
  }
}

namespace {

// The temporaries and second names the publish journals in a directory name: a killed run's files
// that the next command on its prefix completes or puts back.
std::set<std::string> named_in_journals(const std::string& directory) {
  std::set<std::string> named;
  DIR* dir = ::opendir(directory.c_str());
  if (!dir) return named;
  static const std::string journal_end = journal_path("");
  while (const dirent* entry = ::readdir(dir)) {
    const std::string name = entry->d_name;
    if (name.size() <= journal_end.size() ||
        name.compare(name.size() - journal_end.size(), journal_end.size(), journal_end) != 0)
      continue;
    FileDescriptor fd(::open((directory + "/" + name).c_str(), O_RDONLY | O_CLOEXEC));
    if (fd.fd < 0) continue;
    const Journal j = Journal::read(fd.fd);
    for (const std::string& f : j.files) named.insert(j.temporary(f)), named.insert(j.old_copy(f));
  }
  ::closedir(dir);
  return named;
}

}  // namespace

void remove_stale_temporaries(const std::vector<std::string>& final_paths, std::vector<FileFamily> families) {
  for (const std::string& f : final_paths)  // each final path is a family of one name
    families.push_back({directory_of(f), [name = fs::path(f).filename().string()](const std::string& n) { return n == name; }});
  // Each directory is read once, with its journals, however many families it holds.
  std::map<std::string, std::vector<const FileFamily*>> by_directory;
  for (const FileFamily& family : families) by_directory[absolute(family.directory + "/.")].push_back(&family);
  for (const auto& [directory, members] : by_directory) {
    const std::set<std::string> needed = named_in_journals(directory);
    DIR* dir = ::opendir(directory.c_str());
    if (!dir) continue;
    std::vector<std::string> stale;
    while (const dirent* entry = ::readdir(dir)) {
      const std::string name = entry->d_name, path = absolute(directory + "/" + name);
      const std::size_t suffix = name.rfind(".tmp-");  // a second name's ends in ".old": no family's
      if (suffix == std::string::npos || needed.count(path) > 0) continue;
      const std::string final_name = name.substr(0, suffix);
      if (std::any_of(members.begin(), members.end(), [&](const FileFamily* f) { return f->belongs(final_name); }) &&
          temporary_owner_gone(path))
        stale.push_back(path);
    }
    ::closedir(dir);
    for (const std::string& s : stale) std::remove(s.c_str());
  }
}

}  // namespace partet
