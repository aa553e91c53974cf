// The files a run publishes, all or nothing. Each file is written under a unique temporary name
// beside its final name; publish() then moves the whole set into place under a lock on the
// directory, and if any move fails it restores the files that were there before. A run that
// fails or is interrupted leaves the previous files as they were.
#pragma once
#include <functional>
#include <string>
#include <vector>

namespace partet {

class OutputSet {
 public:
  OutputSet();
  ~OutputSet();  // removes the temporaries of a set that was not published
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  // Writes one file: write_file(temporary_path). On failure the temporaries are removed and the
  // error (naming final_path) propagates.
  void add(const std::string& final_path, const std::function<void(const std::string&)>& write_file);
  // Moves every file into place. Throws OutputError (naming the final path) after restoring the
  // previous files when a move fails.
  void publish();
  // Removes the temporaries.
  void discard();

  const std::vector<std::string>& final_paths() const { return finals_; }

 private:
  std::string suffix_;  // unique per run: ".tmp-PID-RANDOM"
  std::vector<std::string> finals_, temporaries_;
  bool published_ = false;
};

// Refuses, before any work, output paths that cannot be written or would overwrite an input or
// each other: an empty path, a path naming a directory, a missing or read-only directory, two
// paths naming the same file. Throws OutputError naming the path.
void check_output_paths(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs);

// Removes temporaries that runs on the same final paths left behind when they were killed
// (their process no longer exists).
void remove_stale_temporaries(const std::vector<std::string>& final_paths);

// On SIGINT or SIGTERM: remove this process's unpublished temporaries, print `message` (when
// not empty) and exit with 128 + the signal's number.
void install_interrupt_handler(const std::string& message);

}  // namespace partet
