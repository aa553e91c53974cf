// The partitions tried after a failure, in order (internal header). "Never worse than TetGen
// alone" is the floor: the last partition is the whole input as one piece.
//
//   1. Along the cut axis asked for: the planes around the failing pieces move to other vertex
//      gaps, twice, the second time with caps without interior points.
//   2. Along each other direction (the coordinate axes from the closest to the main PCA axis,
//      then the PCA axis, or the nearest coordinate axis when PCA was asked), the same way, each
//      from fresh planes and the options asked for (tolerance and cap density reset).
//   3. Fewer pieces along the axis asked for: half as many, then half again, down to two.
//   4. One piece: TetGen alone on the whole input, when it fits in the memory available.
//
// A piece killed from outside (SIGKILL: most often the out-of-memory killer of the node or of
// the job's cgroup), or out of memory under an address-space limit its process inherited
// (ulimit -v), is not the cut's fault, and other cuts or fewer pieces would need as much
// memory or more: the next partition has twice the pieces along the same axis, each about half
// as large, up to kMorePiecesFactor times the pieces asked for; then the run stops saying so.
//
// Diagnosis: a small input (TetGen alone takes a second or two), after the first plane move, and
// any input after a failure that names only whole input triangles (the trouble may be the input
// rather than a cut), is meshed as one piece at once. When that fails too, the trouble is the
// input itself: the error says so, naming the input faces TetGen named, without futile retries.
// When it works, its mesh is kept and is the result at the next failure (a small input), or when
// the other partitions fail too (a large one). A partition identical to the one that just failed is not meshed again. A
// quality bound TetGen cannot meet (its refinement runs away or past its time limit) is tried once more with caps
// without interior points, then reported as what it is: no partition helps.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "job/pipeline.hpp"
#include "partet/errors.hpp"

namespace partet {

// What failed in one attempt, as the plan sees it.
struct AttemptFailure {
  Failure failure;          // the first failure (its text is what the user reads)
  std::vector<int> planes;  // the planes around the failing pieces, or those the failure names
  // The input faces (global indices) the failure names, when every face it names is a whole
  // input triangle; empty otherwise.
  std::vector<std::int64_t> input_faces;
};

// Inputs up to this many faces go to one piece after the first plane move (TetGen alone meshes
// 50k faces in about a second here).
constexpr std::size_t kSmallInputFaces = 50000;

// A run whose pieces are killed for memory tries up to this many times the pieces asked for.
constexpr int kMorePiecesFactor = 4;

class RetryPlan {
 public:
  // available_mb: the memory TetGen alone may use for step 4 (0: unknown, assume it fits).
  RetryPlan(const SurfaceMesh& input, const MeshOptions& asked, double available_mb);

  const MeshOptions& options() const { return current_; }
  int attempt() const { return attempt_; }
  // Where the planes of this attempt aim (fractions of the vertices below each plane), computed
  // once per axis and piece count with the caps first asked for, from the vertices sorted along
  // this attempt's axis.
  const std::vector<double>& fractions(const AxisVertices& along);
  // Whether this attempt's unchanged pieces may reuse the last attempt's results (same axis and
  // piece count).
  bool same_cuts_as_before() const { return same_cuts_; }
  // After a failed attempt: chooses the next one (and says why), or throws MeshingError when no
  // partition can help or none is left.
  void next(const AttemptFailure& failed);
  // The first partition found fewer cut positions along its axis than the pieces asked for need
  // (e.g. a CAD extrusion with two distinct positions along its length): with auto or PCA, the
  // other directions are looked at and the one with the most positions kept. True when the
  // caller should choose the planes again.
  bool fewer_cuts_than_pieces(std::size_t planes);
  // The partition the plan chose is the one that just failed (a plane had no other gap to move
  // to): go on to the next step without meshing it.
  void skip_repeat(const AttemptFailure& failed);
  // This attempt is the one-piece diagnosis (its mesh is kept, not used, when it works).
  bool diagnosing() const { return diagnosing_; }
  // The diagnosis worked: back to the partitions, after the failure that led to it.
  void diagnosis_passed();
  // Every partition failed, and the one-piece mesh of the diagnosis is the result.
  bool use_one_piece_mesh() const { return use_one_piece_mesh_; }
  std::vector<RetryRecord> take_records() { return std::move(records_); }

 private:
  void advance(const AttemptFailure& failed, std::string& note);
  void finish_step(const Failure& failure, const std::vector<int>& planes, const std::string& note);
  [[noreturn]] void input_trouble(const AttemptFailure& failed) const;
  void move_planes(const AttemptFailure& failed, std::string& note);
  bool next_axis(std::string& note);
  bool fewer_pieces(std::string& note);
  bool more_pieces(std::string& note);
  void end_diagnosis();  // back to the partition the diagnosis interrupted
  bool one_piece(std::string& note);
  bool fits_in_memory() const;
  void start_fresh(CutAxis axis, int pieces);
  [[noreturn]] void give_up(const Failure& failure, const std::string& why) const;
  bool tighten_tolerance(const Failure& failure);

  const SurfaceMesh& input_;
  MeshOptions asked_, current_;
  double available_mb_;
  std::vector<CutAxis> axes_;  // in the order tried
  std::size_t axis_index_ = 0;
  int moves_on_axis_ = 0;  // plane moves since this axis (or piece count) started
  bool halving_ = false;   // step 3 has begun
  bool one_piece_tried_ = false;
  bool axis_settled_ = false;  // the first partition's direction is chosen
  std::size_t best_planes_ = 0, best_axis_ = 0;
  bool diagnosing_ = false, one_piece_works_ = false, use_one_piece_mesh_ = false;
  MeshOptions before_diagnosis_;  // the partition the diagnosis interrupted
  int moves_before_diagnosis_ = 0;
  AttemptFailure diagnosed_failure_;  // and its failure
  bool quality_retried_ = false;
  bool same_cuts_ = false;
  int attempt_ = 0;
  std::vector<double> fractions_;
  bool fractions_known_ = false;
  std::vector<RetryRecord> records_;
};

}  // namespace partet
