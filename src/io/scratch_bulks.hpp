// The paper's memory mode: the pieces' bulks wait in files on disk (`--scratch DIR`) between
// their split and the assembly, so the process that welds does not hold them while the last
// pieces are meshed and the seams healed (internal header).
#pragma once
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "stages/merge.hpp"

namespace partet {

// What a scratch store did (for the report).
struct ScratchStats {
  std::int64_t bulks = 0;  // pieces whose bulk was written
  std::int64_t bytes = 0;  // bytes written (a piece split again is written again)
};

// The bulks wait in one file in the directory that has no name there: made nameless (O_TMPFILE),
// or, on a filesystem without that, named as this run's temporaries (file_owner.hpp) and unlinked
// at once. The system frees it however the process ends, killed outright included: Open MPI's
// mpirun sends its ranks SIGKILL milliseconds after SIGTERM, too soon for a rank to clean up. A
// bulk taken back gives its disk space back (a hole punched where the filesystem can). A bulk
// that cannot be written (a full disk) stays in memory, with one warning: the run goes on as
// without the store.
class ScratchBulks : public BulkStore {
 public:
  explicit ScratchBulks(std::string directory);
  ~ScratchBulks() override;
  ScratchBulks(const ScratchBulks&) = delete;
  ScratchBulks& operator=(const ScratchBulks&) = delete;

  bool put(int piece, const TetBlock& bulk) override;
  TetBlock take(int piece) override;
  // Forgets piece's bulk (its disk space given back); nothing when it has none here.
  void drop(int piece);
  bool holds(int piece) const { return slots_.count(piece) > 0; }
  // The pieces whose bulks wait here, ascending.
  std::vector<int> pieces() const {
    std::vector<int> waiting;
    for (const auto& [piece, slot] : slots_) waiting.push_back(piece);
    return waiting;
  }
  const ScratchStats& stats() const { return stats_; }

 private:
  struct Slot {
    std::uint64_t offset = 0, size = 0;
  };
  bool open_file();
  void release(const Slot& slot);
  void fail(const std::string& reason);
  std::string directory_;
  int fd_ = -1;
  std::uint64_t end_ = 0;      // where the next bulk goes
  std::map<int, Slot> slots_;  // by piece: the bulks waiting
  std::set<int> pieces_;       // every piece put
  bool failed_ = false;        // the file could not be made or written: no more tries
  ScratchStats stats_;
};
// Refuses (OptionError) a scratch directory this process cannot write in.
void check_scratch_directory(const std::string& directory);
// Removes the scratch files runs of this host left there (a run killed between naming its file and
// unlinking it, on a filesystem without nameless files; or an earlier partet's files) once their
// process is gone; never another host's, whose runs this one cannot see.
void remove_stale_scratch(const std::string& directory);

}  // namespace partet
