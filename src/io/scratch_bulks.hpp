// The paper's memory mode: the pieces' bulks wait in files on disk (`--scratch DIR`) between
// their split and the assembly, so the process that welds does not hold them while the last
// pieces are meshed and the seams healed (internal header).
#pragma once
#include <cstdint>
#include <map>
#include <set>
#include <string>

#include "stages/merge.hpp"

namespace partet {

// What a scratch store did (for the report).
struct ScratchStats {
  std::int64_t bulks = 0;  // pieces whose bulk was written
  std::int64_t bytes = 0;  // bytes written (a piece split again is written again)
};

// One file per bulk in a directory, named as this run's temporaries are (file_owner.hpp) and
// removed when taken, when the store ends, and by an interrupt. A bulk that cannot be written (a
// full disk) stays in memory, with one warning: the run goes on as without the store.
class ScratchBulks : public BulkStore {
 public:
  explicit ScratchBulks(std::string directory);
  ~ScratchBulks() override;
  ScratchBulks(const ScratchBulks&) = delete;
  ScratchBulks& operator=(const ScratchBulks&) = delete;

  bool put(int piece, const TetBlock& bulk) override;
  TetBlock take(int piece) override;
  bool holds(int piece) const { return files_.count(piece) > 0; }
  const ScratchStats& stats() const { return stats_; }

 private:
  void remove(const std::string& path);
  std::string directory_;
  std::string suffix_;                // this run's temporary suffix
  std::map<int, std::string> files_;  // by piece: the bulks waiting
  std::set<int> pieces_;              // every piece put
  std::int64_t written_ = 0;          // files made, for unique names across attempts
  bool failed_ = false;               // a write failed: no more tries
  ScratchStats stats_;
};

// Refuses (OptionError) a scratch directory this process cannot write in.
void check_scratch_directory(const std::string& directory);
// Removes the scratch files runs of this host left there when they were killed (their process is
// gone); never another host's, whose runs this one cannot see.
void remove_stale_scratch(const std::string& directory);

}  // namespace partet
