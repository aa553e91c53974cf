// Meshed pieces kept on disk (`--checkpoint DIR`), so a run that was stopped (a batch system's
// time limit, a preemption, a crash, Ctrl-C) loses none of the pieces it had meshed: a rerun of
// the same job with the same DIR takes each of them from there instead of meshing it again.
// TetGen is deterministic, so the output is the same as a run never stopped (internal header).
#pragma once
#include <optional>
#include <string>

#include "mesher/tetgen_mesher.hpp"
#include "stages/piece.hpp"

namespace partet {

// One file per piece meshed, named by the piece's index and a hash of what TetGen is given (the
// piece's surface and the TetGen options). It holds that input whole, and a piece is taken only
// when it is exactly the same, so a file of another input, of other options, or a hash collision
// is never taken. Files are written under a temporary name, synced and renamed, so a run killed
// while writing leaves no file that could be taken. Any file that cannot be read back whole is
// skipped (with a warning) and the piece meshed again; a file that cannot be written costs one
// warning, never the run.
class PieceCheckpoint {
 public:
  explicit PieceCheckpoint(std::string directory) : directory_(std::move(directory)) {}

  // What a kept piece is looked up by: the piece and the options as TetGen is given them.
  static std::string key_of(const PieceSurface& piece, const TetgenOptions& tetgen);
  // The reply (serialize_outcome's bytes, a result) kept for piece `index` with exactly this key,
  // its seconds and memory set to 0 (no meshing ran); nothing when there is none.
  std::optional<std::string> find(const std::string& key, int index) const;
  // Keeps a reply that is a result (a failure is not kept: a rerun tries again).
  void keep(const std::string& key, int index, const std::string& reply) const;

 private:
  std::string path_of(const std::string& key, int index) const;
  std::string directory_;
};

// Throws OptionError when DIR cannot be made or written ("--checkpoint: ..."). Makes it if
// missing (its parent must exist).
void check_checkpoint_directory(const std::string& directory);

}  // namespace partet
