#include "job/retry_plan.hpp"

#include <algorithm>
#include <cstdio>

#include "common/log.hpp"
#include "runner/piece_runner.hpp"
#include "stages/piece_cost.hpp"

namespace partet {
namespace {

constexpr int kMovesPerCut = 2;  // plane moves along one axis (or piece count) before the next

std::string listed(const std::vector<std::int64_t>& faces) {
  std::string text;
  const std::size_t shown = std::min<std::size_t>(faces.size(), 5);
  for (std::size_t i = 0; i < shown; ++i)
    text += (i == 0 ? "" : i + 1 == shown && shown == faces.size() ? " and " : ", ") + std::to_string(faces[i]);
  if (faces.size() > shown) text += " (and " + std::to_string(faces.size() - shown) + " more)";
  return text;
}

bool quality_unmet(const Failure& f, const MeshOptions& options) {
  return f.kind == FailureKind::runaway || (f.kind == FailureKind::timed_out && !options.tetgen.quality.empty());
}

}  // namespace

RetryPlan::RetryPlan(const SurfaceMesh& input, const MeshOptions& asked, double available_mb)
    : input_(input), asked_(asked), current_(asked), available_mb_(available_mb) {
  const std::vector<CutAxis> coordinates = coordinate_axes_by_closeness(input);
  if (asked.axis == CutAxis::pca) axes_.push_back(CutAxis::pca);
  if (asked.axis == CutAxis::x || asked.axis == CutAxis::y || asked.axis == CutAxis::z) axes_.push_back(asked.axis);
  for (CutAxis a : coordinates)
    if (std::find(axes_.begin(), axes_.end(), a) == axes_.end()) axes_.push_back(a);
  if (asked.axis != CutAxis::pca) axes_.push_back(CutAxis::pca);
  // The axis asked for stays as given (auto is the closest coordinate axis: the same planes).
  current_.plane_shifts.assign(asked.pieces > 1 ? static_cast<std::size_t>(asked.pieces) - 1 : 0, 0);
  one_piece_tried_ = asked.pieces <= 1;  // one piece asked for: its failure is the input's
  axis_settled_ = asked.axis != CutAxis::coordinate_near_pca && asked.axis != CutAxis::pca;
}

const std::vector<double>& RetryPlan::fractions(const AxisVertices& along) {
  if (!fractions_known_) {
    fractions_ = current_.balance == Balance::cost && current_.pieces > 1
                     ? cost_balanced_fractions(input_, along, current_.pieces, asked_.density)
                     : std::vector<double>();
    fractions_known_ = true;
  }
  return fractions_;
}

void RetryPlan::next(const AttemptFailure& failed) {
  const Failure& f = failed.failure;
  if (f.kind == FailureKind::injected) give_up(f, "");  // a test hook: the same piece fails whatever the cut
  if (attempt_ + 1 >= std::max(1, asked_.max_attempts))
    give_up(f, " (after " + std::to_string(attempt_ + 1) + " partitions)");
  std::string note;
  if (one_piece_works_ && input_.triangles.size() <= kSmallInputFaces) {
    // TetGen alone took a second or two: more partitions would cost more than they could save.
    use_one_piece_mesh_ = true;
    note = "; using the input meshed as one piece, as TetGen alone would";
  } else if (f.kind == FailureKind::killed || f.kind == FailureKind::out_of_memory) {
    if (diagnosing_) end_diagnosis();  // the input as one piece does not fit: the cuts go on, in smaller pieces
    if (!more_pieces(note)) give_up(f, " (with " + std::to_string(current_.pieces) + " pieces)");
  } else if (quality_unmet(f, current_)) {
    // Dense caps can keep TetGen refining where plain ones let it finish; beyond that, no cut helps.
    if (quality_retried_ || current_.density <= 0 || current_.pieces <= 1) {
      Failure unmet = f;
      unmet.piece = -1;
      unmet.message = f.text() + "; the quality bound " + current_.tetgen.quality +
                      " cannot be met here (bounds below about 1.414, or with a large angle, often cannot), and no "
                      "partition changes that";
      throw InputMeshingError(unmet);
    }
    quality_retried_ = true;
    current_.density = 0;
    same_cuts_ = true;
    note = "; trying caps without interior points";
  } else if (current_.pieces <= 1 && one_piece_tried_) {
    if (!tighten_tolerance(f)) input_trouble(failed);
    note = "; retrying with a tighter tolerance";
    same_cuts_ = true;
  } else if (!one_piece_tried_ && current_.pieces > 1 && fits_in_memory() &&
             ((f.kind == FailureKind::changed_boundary && !failed.input_faces.empty()) ||
              (input_.triangles.size() <= kSmallInputFaces && attempt_ >= 1))) {
    // Is it the input? One piece tells, and its mesh is kept in case the cuts keep failing.
    before_diagnosis_ = current_;
    moves_before_diagnosis_ = moves_on_axis_;
    diagnosed_failure_ = failed;
    diagnosing_ = one_piece_tried_ = true;
    start_fresh(axes_.front(), 1);
    note = "; meshing the input as one piece, as TetGen alone would, to tell whether the input is the trouble";
  } else {
    advance(failed, note);
  }
  finish_step(f, failed.planes, note);
}

bool RetryPlan::fewer_cuts_than_pieces(std::size_t planes) {
  if (axis_settled_ || attempt_ > 0) return false;
  if (planes + 1 >= static_cast<std::size_t>(asked_.pieces)) {
    axis_settled_ = true;
    return false;
  }
  if (planes > best_planes_ || axis_index_ == 0) best_planes_ = planes, best_axis_ = axis_index_;
  if (axis_index_ + 1 < axes_.size()) {
    ++axis_index_;
    start_fresh(axes_[axis_index_], asked_.pieces);
    return true;
  }
  // None has enough: the one with the most goes first, the retries take the rest in order.
  axis_settled_ = true;
  const CutAxis best = axes_[best_axis_];
  axes_.erase(axes_.begin() + static_cast<std::ptrdiff_t>(best_axis_));
  axes_.insert(axes_.begin(), best);
  axis_index_ = 0;
  start_fresh(best, asked_.pieces);
  return true;
}

void RetryPlan::skip_repeat(const AttemptFailure& failed) {
  moves_on_axis_ = kMovesPerCut;  // no plane can move further: moving on
  std::string note;
  advance(failed, note);
  log::debug("the planes cannot move further" + note);
}

void RetryPlan::end_diagnosis() {
  diagnosing_ = false;
  current_ = before_diagnosis_;
  moves_on_axis_ = moves_before_diagnosis_;
  fractions_known_ = false;
}

void RetryPlan::diagnosis_passed() {
  end_diagnosis();
  one_piece_works_ = true;
  std::string note;
  advance(diagnosed_failure_, note);
  log::warning("the input meshes as one piece (that mesh is kept in case the cuts keep failing)" + note);
  ++attempt_;
}

void RetryPlan::finish_step(const Failure& failure, const std::vector<int>& planes, const std::string& note) {
  log::warning("attempt " + std::to_string(attempt_ + 1) + " failed: " + failure.text() + note);
  records_.push_back({attempt_, failure.text(), planes});
  ++attempt_;
}

// The next partition after a failure: plane moves, other directions, fewer pieces, one piece.
void RetryPlan::advance(const AttemptFailure& failed, std::string& note) {
  if (tighten_tolerance(failed.failure)) {
    note = "; retrying with a tighter tolerance";
    same_cuts_ = true;
  } else if (moves_on_axis_ < kMovesPerCut && current_.pieces > 1) {
    move_planes(failed, note);
  } else if (!next_axis(note) && !fewer_pieces(note) && !one_piece(note)) {
    give_up(failed.failure, " (after " + std::to_string(attempt_ + 1) + " partitions" +
                                (one_piece_tried_ ? ")" : "; TetGen alone would not fit in the memory available)"));
  }
}

void RetryPlan::input_trouble(const AttemptFailure& failed) const {
  const Failure& f = failed.failure;
  Failure trouble = f;
  trouble.piece = -1;
  std::string what;
  if (f.kind == FailureKind::changed_boundary)
    what = "TetGen alone cannot mesh this input without putting points on its surface" +
           (failed.input_faces.empty() ? std::string() : " (on input faces " + listed(failed.input_faces) + ")");
  else if (f.kind == FailureKind::self_intersection || f.kind == FailureKind::too_close)
    what = "TetGen alone takes " +
           (failed.input_faces.empty() ? std::string("parts of this input")
                                       : "input faces " + listed(failed.input_faces)) +
           " for intersecting or too close (within its tolerance)";
  else if (f.kind == FailureKind::timed_out)
    what = "the input as one piece (as TetGen alone would mesh it) did not finish: " + f.message;
  else
    what = "TetGen alone fails on this input too: " + f.message;
  // TetGen's own trouble keeping every input triangle whole (-Y): without that promise it may
  // manage. Faces it takes for intersecting stay so either way; and more time is what a time
  // limit needs, not split faces.
  const bool split_faces_may_help =
      f.kind != FailureKind::self_intersection && f.kind != FailureKind::too_close && f.kind != FailureKind::timed_out;
  trouble.message =
      what + (f.kind == FailureKind::timed_out ? "" : "; partet keeps every input triangle, so no partition can help");
  throw InputMeshingError(trouble, split_faces_may_help);
}

void RetryPlan::move_planes(const AttemptFailure& failed, std::string& note) {
  std::vector<int> planes = failed.planes;
  if (planes.empty())
    for (std::size_t j = 0; j < current_.plane_shifts.size(); ++j) planes.push_back(static_cast<int>(j));
  std::sort(planes.begin(), planes.end());
  planes.erase(std::unique(planes.begin(), planes.end()), planes.end());
  note = "; moving cut plane(s)";
  for (int j : planes) {
    note += " " + std::to_string(j);
    if (static_cast<std::size_t>(j) < current_.plane_shifts.size()) ++current_.plane_shifts[j];
  }
  // The second move also drops the caps' interior points: less for TetGen to recover there.
  if (++moves_on_axis_ == kMovesPerCut && current_.density > 0) {
    current_.density = 0;
    note += " and using caps without interior points";
  }
  same_cuts_ = true;
}

void RetryPlan::start_fresh(CutAxis axis, int pieces) {
  const int max_attempts = current_.max_attempts;
  current_ = asked_;
  current_.max_attempts = max_attempts;
  current_.axis = axis;
  current_.pieces = pieces;
  current_.plane_shifts.assign(pieces > 1 ? static_cast<std::size_t>(pieces) - 1 : 0, 0);
  fractions_known_ = false;
  moves_on_axis_ = 0;
  same_cuts_ = false;
}

bool RetryPlan::next_axis(std::string& note) {
  if (halving_ || axis_index_ + 1 >= axes_.size()) return false;
  ++axis_index_;
  start_fresh(axes_[axis_index_], asked_.pieces);
  note = std::string("; the cuts kept failing: cutting along ") +
         (axes_[axis_index_] == CutAxis::pca ? "the main (PCA) axis"
                                             : std::string("the ") + axis_name(axes_[axis_index_]) + " axis") +
         " instead";
  return true;
}

bool RetryPlan::fewer_pieces(std::string& note) {
  const int pieces = (halving_ ? current_.pieces : asked_.pieces) / 2;
  if (pieces < 2) return false;
  halving_ = true;
  start_fresh(axes_.front(), pieces);
  note = "; the cuts kept failing along every direction: using " + std::to_string(pieces) + " pieces instead of " +
         std::to_string(asked_.pieces);
  return true;
}

bool RetryPlan::more_pieces(std::string& note) {
  const int pieces = 2 * std::max(1, current_.pieces);
  if (pieces > kMorePiecesFactor * std::max(1, asked_.pieces)) return false;
  note = "; most likely out of memory: using " + std::to_string(pieces) + " pieces instead of " +
         std::to_string(current_.pieces) + ", each about half as large";
  start_fresh(current_.axis, pieces);
  return true;
}

bool RetryPlan::fits_in_memory() const {
  const double need_mb = 1.2 * kTetgenKilobytesPerTriangle * static_cast<double>(input_.triangles.size()) / 1024;
  return available_mb_ <= 0 || need_mb <= available_mb_;
}

bool RetryPlan::one_piece(std::string& note) {
  if (one_piece_works_) {
    use_one_piece_mesh_ = true;
    note = "; using the input meshed as one piece, as TetGen alone would";
    return true;
  }
  if (one_piece_tried_ || !fits_in_memory()) return false;
  one_piece_tried_ = true;
  start_fresh(axes_.front(), 1);
  note = "; meshing the input as one piece, as TetGen alone would";
  return true;
}

bool RetryPlan::tighten_tolerance(const Failure& failure) {
  // TetGen's coplanarity tolerance is relative to the model's size: for a valid input it called
  // self-intersecting or too close (a very thin solid), a tiny one is tried once per partition
  // direction.
  if ((failure.kind != FailureKind::self_intersection && failure.kind != FailureKind::too_close) ||
      !current_.tetgen.tolerance.empty())
    return false;
  current_.tetgen.tolerance = "1e-16";
  return true;
}

void RetryPlan::give_up(const Failure& failure, const std::string& why) const {
  Failure final = failure;
  final.message = failure.text() + why;
  final.piece = -1;
  throw MeshingError(final);
}

}  // namespace partet
