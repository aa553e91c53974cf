// The files a run publishes, all or nothing. Each file is written under a temporary name beside
// its final name (locked by this run, named after its host and process, so that no other run
// takes it for a leftover). publish() then moves the whole set into place:
//
//   1. it takes PREFIX.partet-publish, the set's journal, which is also the lock that makes
//      publishes at one prefix take turns (a journal a killed run left is completed first);
//   2. it lists in the journal every move it is about to make, and syncs it;
//   3. with interrupts held off, it keeps the previous files aside (hard links where the
//      filesystem has them), moves the new ones in, and removes the previous set's leftovers
//      (files of the previous set the new one does not have, e.g. .pvtu piece files of a run
//      with more pieces); if a move fails it puts every previous file back;
//   4. it removes the journal.
//
// So a signal at any moment leaves the complete previous set or the complete new set, and the
// interrupt message says which. Only a SIGKILL or a power cut during step 3 can stop it half
// way; the journal then names every file, and the next partet command on the prefix (mesh,
// check, info) completes the move.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace partet {

class OutputSet {
 public:
  // The set's journal (and lock) is journal_path, beside the main output (PREFIX.partet-publish).
  explicit OutputSet(std::string journal_path);
  ~OutputSet();  // removes the temporaries of a set that was not published
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  // Writes one file: write_file(temporary_path). On failure the temporaries are removed and the
  // error (naming final_path) propagates.
  void add(const std::string& final_path, const std::function<void(const std::string&)>& write_file);
  // Waits for the files write_file closed in the background (io/buffered_file.hpp); on a
  // failure the temporaries are removed and the error propagates. publish does it first.
  void finish_writes();
  // Files in `directory` whose names `belongs` accepts are part of the set when this run does not
  // write them: publishing removes them with the previous set (looked up under the lock).
  void supersede(const std::string& directory, std::function<bool(const std::string& name)> belongs);
  // Moves every file into place. Throws OutputError (naming the final path) after restoring the
  // previous files when a move fails, or when another run holds the lock for longer than
  // lock_wait_seconds.
  void publish();
  // Removes the temporaries.
  void discard();

  const std::vector<std::string>& final_paths() const { return finals_; }
  // What each file's temporary name adds to its final name.
  const std::string& temporary_name_suffix() const;
  // The longest temporary or set-aside name this set makes beside final_path.
  static std::size_t longest_extra_name(const std::string& final_path);

  double lock_wait_seconds = 120;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<std::string> finals_;
};

// The journal beside a prefix's files.
std::string journal_path(const std::string& prefix);

// Completes a publish at this prefix that a killed run left half done (its journal names every
// file), waiting at most wait_seconds for a live one to end. Returns a line saying what it did
// (empty when there was nothing to do). Throws OutputError when a live run holds it too long.
std::string settle_publish(const std::string& prefix, double wait_seconds = 120);

// Refuses, before any work, output paths that cannot be written or would overwrite an input or
// each other: an empty path, a path naming a directory or a symbolic link, a missing or read-only
// directory, two paths naming the same file, names too long for the filesystem once the
// temporary suffix is added. Throws OptionError naming the path.
void check_output_paths(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs);

// Files of a set that only the mesh names (a .pvtu set's piece files, the MSH partitions): their
// directory and which names are theirs.
struct FileFamily {
  std::string directory;
  std::function<bool(const std::string& name)> belongs;
};

// Removes temporaries that runs on the same final paths, or on names of the families, left behind
// when they were killed and their reaper could not remove them (it was killed too, or the node
// went down): only those whose run is gone for sure (see file_owner.hpp), never a live run's, on
// any host, and never one that a publish journal still needs.
void remove_stale_temporaries(const std::vector<std::string>& final_paths, std::vector<FileFamily> families = {});

}  // namespace partet
