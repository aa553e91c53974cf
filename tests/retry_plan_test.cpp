// The order of partitions tried after failures (src/job/retry_plan.hpp), driven with made-up
// failures: no meshing happens here.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "partet/errors.hpp"
#include "stages/generate.hpp"
#include "job/retry_plan.hpp"

namespace partet {
namespace {

// A sphere above the small-input size, so no early one-piece diagnosis.
const SurfaceMesh& large_input() {
  static const SurfaceMesh s = generate_surface("sphere", 2 * static_cast<int>(kSmallInputFaces));
  return s;
}

MeshOptions asked(int pieces, CutAxis axis = CutAxis::coordinate_near_pca) {
  MeshOptions o;
  o.pieces = pieces;
  o.axis = axis;
  o.density = 0.25;
  return o;
}

AttemptFailure failure(FailureKind kind, std::vector<int> planes = {}, std::vector<std::int64_t> input_faces = {}) {
  AttemptFailure f;
  f.failure = Failure(kind, 0, planes, "made-up failure");
  f.planes = std::move(planes);
  f.input_faces = std::move(input_faces);
  return f;
}

// One partition as the plan describes it.
struct Step {
  CutAxis axis;
  int pieces;
  double density;
  std::vector<int> shifts;
  bool operator==(const Step& o) const {
    return axis == o.axis && pieces == o.pieces && density == o.density && shifts == o.shifts;
  }
};
std::ostream& operator<<(std::ostream& out, const Step& s) {
  out << axis_name(s.axis) << " K=" << s.pieces << " density " << s.density << " shifts";
  for (int v : s.shifts) out << ' ' << v;
  return out;
}
Step step(const RetryPlan& plan) {
  const MeshOptions& o = plan.options();
  return {o.axis, o.pieces, o.density, o.plane_shifts};
}

TEST(RetryPlan, MovesPlanesThenOtherAxesThenFewerPiecesThenOnePiece) {
  const SurfaceMesh& input = large_input();
  RetryPlan plan(input, asked(8, CutAxis::x), 0);
  std::vector<CutAxis> others;  // the other coordinate axes from the closest to PCA, then PCA
  for (CutAxis a : coordinate_axes_by_closeness(input))
    if (a != CutAxis::x) others.push_back(a);
  others.push_back(CutAxis::pca);
  std::vector<Step> seen{step(plan)};
  // Every attempt fails between pieces 2 and 3 (planes 2 and 3 around piece 3).
  for (int i = 0; i < 40 && plan.options().pieces > 1; ++i) {
    plan.next(failure(FailureKind::tetgen_error, {2, 3}));
    seen.push_back(step(plan));
  }
  ASSERT_GE(seen.size(), 3u);
  const std::vector<int> none(7, 0), once{0, 0, 1, 1, 0, 0, 0}, twice{0, 0, 2, 2, 0, 0, 0};
  // The axis asked for: the failing planes move twice, the second time with plain caps.
  EXPECT_EQ(seen[0], (Step{CutAxis::x, 8, 0.25, none}));
  EXPECT_EQ(seen[1], (Step{CutAxis::x, 8, 0.25, once}));
  EXPECT_EQ(seen[2], (Step{CutAxis::x, 8, 0.0, twice}));
  // Every other direction, from fresh planes and the caps asked for.
  std::size_t at = 3;
  for (CutAxis a : others) {
    ASSERT_LT(at + 2, seen.size());
    EXPECT_EQ(seen[at], (Step{a, 8, 0.25, none})) << axis_name(a);
    EXPECT_EQ(seen[at + 1], (Step{a, 8, 0.25, once})) << axis_name(a);
    EXPECT_EQ(seen[at + 2], (Step{a, 8, 0.0, twice})) << axis_name(a);
    at += 3;
  }
  // Then half as many pieces along the first axis, then half again, then one piece.
  ASSERT_EQ(seen.size(), at + 3 + 3 + 1);
  EXPECT_EQ(seen[at], (Step{CutAxis::x, 4, 0.25, {0, 0, 0}}));
  EXPECT_EQ(seen[at + 3], (Step{CutAxis::x, 2, 0.25, {0}}));
  EXPECT_EQ(seen.back().pieces, 1);
  EXPECT_FALSE(plan.diagnosing());  // the last resort, not a diagnosis: its mesh is the result
  EXPECT_EQ(plan.take_records().size(), seen.size() - 1);
  // One piece failing too is the input's trouble: no more partitions.
  try {
    plan.next(failure(FailureKind::tetgen_error));
    FAIL() << "no error";
  } catch (const MeshingError& e) {
    EXPECT_NE(std::string(e.what()).find("TetGen alone fails on this input too"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no partition can help"), std::string::npos) << e.what();
  }
}

// The input as one piece out of time: more time is what it needs, not split faces, and it is not
// said to be TetGen's trouble with the input.
TEST(RetryPlan, OnePieceOutOfTimeIsNotTheInputsFault) {
  RetryPlan plan(large_input(), asked(1), 0);
  try {
    plan.next(failure(FailureKind::timed_out));
    FAIL() << "no error";
  } catch (const InputMeshingError& e) {
    EXPECT_EQ(e.failure.kind, FailureKind::timed_out);
    EXPECT_FALSE(e.split_faces_may_help);
    EXPECT_NE(std::string(e.what()).find("the input as one piece (as TetGen alone would mesh it) did not finish: "
                                         "made-up failure"),
              std::string::npos)
        << e.what();
    EXPECT_EQ(std::string(e.what()).find("no partition can help"), std::string::npos) << e.what();
  }
}

TEST(RetryPlan, PcaFallsBackToEveryCoordinateAxis) {
  RetryPlan plan(large_input(), asked(4, CutAxis::pca), 0);
  std::vector<CutAxis> axes{plan.options().axis};
  for (int i = 0; i < 11; ++i) {  // four directions, three partitions each
    plan.next(failure(FailureKind::changed_boundary, {0}));
    if (plan.options().axis != axes.back()) axes.push_back(plan.options().axis);
  }
  const std::vector<CutAxis> coordinates = coordinate_axes_by_closeness(large_input());
  ASSERT_EQ(axes.size(), 4u);
  EXPECT_EQ(axes[0], CutAxis::pca);
  EXPECT_EQ(std::vector<CutAxis>(axes.begin() + 1, axes.end()), coordinates);
  plan.next(failure(FailureKind::changed_boundary, {0}));
  EXPECT_EQ(plan.options().axis, CutAxis::pca);  // then fewer pieces, along the axis asked for
  EXPECT_EQ(plan.options().pieces, 2);
}

TEST(RetryPlan, EachDirectionStartsWithTheToleranceAskedFor) {
  // A tighter tolerance is tried once per direction, and a new direction starts without it: the
  // tolerance that helped nothing on one axis must not be carried to the next (the finned part).
  RetryPlan plan(large_input(), asked(4, CutAxis::x), 0);
  plan.next(failure(FailureKind::too_close, {1}));
  EXPECT_EQ(plan.options().tetgen.tolerance, "1e-16");
  EXPECT_EQ(plan.options().plane_shifts, (std::vector<int>{0, 0, 0}));  // same cuts, tighter tolerance
  EXPECT_TRUE(plan.same_cuts_as_before());
  while (plan.options().axis == CutAxis::x) plan.next(failure(FailureKind::too_close, {1}));
  EXPECT_EQ(plan.options().tetgen.tolerance, "");
  EXPECT_EQ(plan.options().density, 0.25);
  EXPECT_FALSE(plan.same_cuts_as_before());
}

TEST(RetryPlan, SmallInputIsDiagnosedAsOnePieceAfterTheFirstMove) {
  const SurfaceMesh input = generate_surface("sphere", 2000);
  RetryPlan plan(input, asked(6), 0);
  plan.next(failure(FailureKind::tetgen_error, {1}));
  EXPECT_FALSE(plan.diagnosing());
  EXPECT_EQ(plan.options().pieces, 6);
  plan.next(failure(FailureKind::tetgen_error, {1}));
  ASSERT_TRUE(plan.diagnosing());
  EXPECT_EQ(plan.options().pieces, 1);
  // It works: back to the partitions, where the interrupted one left off (its second move).
  plan.diagnosis_passed();
  EXPECT_FALSE(plan.diagnosing());
  EXPECT_EQ(plan.options().pieces, 6);
  EXPECT_EQ(plan.options().density, 0.0);
  EXPECT_EQ(plan.options().plane_shifts, (std::vector<int>{0, 2, 0, 0, 0}));
  // A small input: the next failure takes the one-piece mesh (more partitions would cost more
  // than TetGen alone took).
  plan.next(failure(FailureKind::tetgen_error, {1}));
  EXPECT_TRUE(plan.use_one_piece_mesh());
  EXPECT_EQ(plan.take_records().size(), 3u);
}

TEST(RetryPlan, LargeInputKeepsTheOnePieceMeshUntilEveryPartitionFailed) {
  RetryPlan plan(large_input(), asked(4, CutAxis::x), 0);
  plan.next(failure(FailureKind::changed_boundary, {1}, {5}));  // names an input face: diagnosed
  ASSERT_TRUE(plan.diagnosing());
  plan.diagnosis_passed();
  EXPECT_EQ(plan.options().pieces, 4);
  int attempts = 0;
  std::vector<CutAxis> axes;
  while (!plan.use_one_piece_mesh()) {
    ASSERT_LT(++attempts, 40);
    EXPECT_FALSE(plan.diagnosing());
    EXPECT_GT(plan.options().pieces, 1);
    if (axes.empty() || axes.back() != plan.options().axis) axes.push_back(plan.options().axis);
    plan.next(failure(FailureKind::tetgen_error, {1}));
  }
  EXPECT_EQ(axes.size(), 5u) << "x, the two other axes, PCA, then fewer pieces along x";
}

TEST(RetryPlan, FailureNamingInputFacesIsDiagnosedAtOnceAndNamedWhenItIsTheInput) {
  RetryPlan plan(large_input(), asked(8), 0);
  plan.next(failure(FailureKind::changed_boundary, {3}, {17, 4, 99}));
  ASSERT_TRUE(plan.diagnosing());
  EXPECT_EQ(plan.options().pieces, 1);
  try {
    plan.next(failure(FailureKind::changed_boundary, {}, {4, 17, 99}));
    FAIL() << "no error";
  } catch (const MeshingError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("TetGen alone cannot mesh this input without putting points on its surface (on input faces 4, "
                        "17 and 99)"),
              std::string::npos)
        << what;
    EXPECT_EQ(e.failure.piece, -1);
    EXPECT_EQ(e.failure.kind, FailureKind::changed_boundary);
  }
  EXPECT_EQ(plan.attempt(), 1);  // one partition and one piece: no futile retries
}

TEST(RetryPlan, FailureNamingCutFacesGoesOnWithTheCuts) {
  RetryPlan plan(large_input(), asked(8), 0);
  plan.next(failure(FailureKind::changed_boundary, {3}));  // no whole input face named: a cap's trouble
  EXPECT_FALSE(plan.diagnosing());
  EXPECT_EQ(plan.options().pieces, 8);
  EXPECT_EQ(plan.options().plane_shifts[3], 1);
}

TEST(RetryPlan, QualityThatCannotBeMetIsTriedOnceWithPlainCapsThenReported) {
  MeshOptions o = asked(4);
  o.tetgen.quality = "1.05/20";
  RetryPlan plan(large_input(), o, 0);
  plan.next(failure(FailureKind::runaway, {1}));
  EXPECT_EQ(plan.options().density, 0.0);
  EXPECT_EQ(plan.options().plane_shifts, (std::vector<int>{0, 0, 0}));
  try {
    plan.next(failure(FailureKind::runaway, {1}));
    FAIL() << "no error";
  } catch (const MeshingError& e) {
    EXPECT_NE(std::string(e.what()).find("the quality bound 1.05/20 cannot be met here"), std::string::npos) << e.what();
  }
}

TEST(RetryPlan, OnePieceOnlyWhenTetGenAloneFitsInMemory) {
  RetryPlan plan(large_input(), asked(4, CutAxis::x), 1.0);  // 1 MB: TetGen alone cannot fit
  try {
    for (int i = 0; i < 40; ++i) {
      plan.next(failure(FailureKind::tetgen_error, {0}));
      ASSERT_GT(plan.options().pieces, 1);
    }
    FAIL() << "no error";
  } catch (const MeshingError& e) {
    EXPECT_NE(std::string(e.what()).find("TetGen alone would not fit in the memory available"), std::string::npos)
        << e.what();
  }
}

TEST(RetryPlan, PiecesKilledForMemoryDoubleAlongTheSameAxisUpToFourTimesThoseAskedThenStop) {
  RetryPlan plan(large_input(), asked(4, CutAxis::x), 0);
  plan.next(failure(FailureKind::killed, {1}));
  EXPECT_EQ(step(plan), (Step{CutAxis::x, 8, 0.25, std::vector<int>(7, 0)}));
  plan.next(failure(FailureKind::killed, {3}));
  EXPECT_EQ(step(plan), (Step{CutAxis::x, 16, 0.25, std::vector<int>(15, 0)}));
  try {
    plan.next(failure(FailureKind::killed, {0}));
    FAIL() << "no error";
  } catch (const MeshingError& e) {
    EXPECT_EQ(e.failure.kind, FailureKind::killed);
    EXPECT_NE(std::string(e.what()).find("made-up failure (with 16 pieces)"), std::string::npos) << e.what();
  }
  // Killed while the input is meshed as one piece to diagnose a failure: the cuts go on, twice as many.
  RetryPlan diagnosed(large_input(), asked(3, CutAxis::x), 0);
  diagnosed.next(failure(FailureKind::changed_boundary, {1}, {17}));
  ASSERT_TRUE(diagnosed.diagnosing());
  diagnosed.next(failure(FailureKind::killed));
  EXPECT_FALSE(diagnosed.diagnosing());
  EXPECT_EQ(step(diagnosed), (Step{CutAxis::x, 6, 0.25, std::vector<int>(5, 0)}));
  // One piece asked for (TetGen alone): two halves next.
  RetryPlan alone(large_input(), asked(1), 0);
  alone.next(failure(FailureKind::killed));
  EXPECT_EQ(alone.options().pieces, 2);
  // Out of memory under a limit the process inherited (ulimit -v): the same remedy.
  RetryPlan limited(large_input(), asked(4, CutAxis::x), 0);
  limited.next(failure(FailureKind::out_of_memory, {2}));
  EXPECT_EQ(step(limited), (Step{CutAxis::x, 8, 0.25, std::vector<int>(7, 0)}));
}

TEST(RetryPlan, InjectedFailuresAndTheAttemptLimitEndAtOnce) {
  RetryPlan injected(large_input(), asked(4), 0);
  EXPECT_THROW(injected.next(failure(FailureKind::injected, {0})), MeshingError);
  MeshOptions o = asked(4);
  o.max_attempts = 2;
  RetryPlan limited(large_input(), o, 0);
  limited.next(failure(FailureKind::tetgen_error, {0}));
  try {
    limited.next(failure(FailureKind::tetgen_error, {0}));
    FAIL() << "no error";
  } catch (const MeshingError& e) {
    EXPECT_NE(std::string(e.what()).find("(after 2 partitions)"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace partet
