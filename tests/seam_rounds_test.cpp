// Seam healing rounds: which vertices left to remove are re-meshed next. Vertices sharing tets
// heal together; groups whose stars meet take turns only where healing them at once would make a
// part larger than the largest part of one group.
#include <gtest/gtest.h>

#include <vector>

#include "stages/seam_rounds.hpp"

namespace partet {
namespace {

constexpr std::int32_t kFirst = 100;  // removed vertices are 100..; ordinary ones below

// A removed vertex's group by id (-1: not to be removed).
std::vector<int> groups(std::initializer_list<std::pair<std::int32_t, int>> of, std::size_t count = 12) {
  std::vector<int> group(count, -1);
  for (const auto& [v, g] : of) group[v - kFirst] = g;
  return group;
}

// Vertices 100 and 101 (group 0) share tets; 104 (group 1) meets 101 in one tet; 105 (group 1)
// is on its own. Only the vertex ids matter to the plan.
TetMesh two_groups_meeting() {
  TetMesh mesh;
  mesh.tets = {{0, 1, 2, 100}, {1, 2, 3, 100},   {2, 3, 4, 100},   {3, 4, 5, 101}, {4, 5, 6, 101},
               {5, 6, 7, 101}, {6, 7, 100, 101}, {7, 8, 101, 104}, {8, 9, 104, 0}, {9, 0, 1, 104},
               {0, 2, 4, 105}, {1, 3, 5, 105},   {0, 1, 2, 3}};  // no removed vertex
  return mesh;
}

TEST(SeamRounds, StarTetsAreTheTetsWithAVertexLeft) {
  const TetMesh mesh = two_groups_meeting();
  const SeamRound round = plan_seam_round(mesh, kFirst, groups({{100, 0}, {101, 0}, {104, 1}, {105, 1}}));
  EXPECT_EQ(round.star_tets, (std::vector<std::int32_t>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11}));
  // Vertices not to be removed are not: the tets with only 104 and 105 are no star tets then.
  const SeamRound only_group_0 = plan_seam_round(mesh, kFirst, groups({{100, 0}, {101, 0}}));
  EXPECT_EQ(only_group_0.star_tets, (std::vector<std::int32_t>{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(only_group_0.heals[100 - kFirst], 1);
  EXPECT_EQ(only_group_0.heals[104 - kFirst], 0);
}

TEST(SeamRounds, GroupsThatDoNotMeetHealAtOnce) {
  TetMesh mesh = two_groups_meeting();
  mesh.tets[7] = {7, 8, 101, 9};  // 104 no longer shares a tet with 101
  const SeamRound round = plan_seam_round(mesh, kFirst, groups({{100, 0}, {101, 0}, {104, 1}, {105, 1}}));
  for (std::int32_t v : {100, 101, 104, 105}) EXPECT_EQ(round.heals[v - kFirst], 1) << v;
}

TEST(SeamRounds, MeetingGroupsTakeTurnsLargestFirst) {
  // The component {100, 101, 104} has 10 star tets, more than the largest part of one group
  // ({100, 101}: 8), so group 0 (8 of them) heals first and 104 waits; 105, a component of its
  // own, heals now.
  const TetMesh mesh = two_groups_meeting();
  std::vector<int> group = groups({{100, 0}, {101, 0}, {104, 1}, {105, 1}});
  const SeamRound first = plan_seam_round(mesh, kFirst, group);
  EXPECT_EQ(first.heals[100 - kFirst], 1);
  EXPECT_EQ(first.heals[101 - kFirst], 1);
  EXPECT_EQ(first.heals[104 - kFirst], 0);
  EXPECT_EQ(first.heals[105 - kFirst], 1);
  // Once they are removed, the vertex left heals in the next round.
  for (std::size_t v = 0; v < group.size(); ++v)
    if (first.heals[v]) group[v] = -1;
  const SeamRound second = plan_seam_round(mesh, kFirst, group);
  EXPECT_EQ(second.heals[104 - kFirst], 1);
  EXPECT_EQ(second.star_tets, (std::vector<std::int32_t>{7, 8, 9}));
}

TEST(SeamRounds, MeetingGroupsHealAtOnceWhenThatMakesNoLargerPart) {
  // A larger part elsewhere (110, group 2, in 12 tets) sets the bar: the meeting component of 10
  // star tets is no larger, so it heals as one part in this round.
  TetMesh mesh = two_groups_meeting();
  for (std::int32_t i = 0; i < 12; ++i) mesh.tets.push_back({i % 10, (i + 1) % 10, (i + 2) % 10, 110});
  const SeamRound round = plan_seam_round(mesh, kFirst, groups({{100, 0}, {101, 0}, {104, 1}, {105, 1}, {110, 2}}));
  for (std::int32_t v : {100, 101, 104, 105, 110}) EXPECT_EQ(round.heals[v - kFirst], 1) << v;
}

TEST(SeamRounds, NothingLeftPlansNothing) {
  const SeamRound round = plan_seam_round(two_groups_meeting(), kFirst, groups({}));
  EXPECT_TRUE(round.star_tets.empty());
  for (char heals : round.heals) EXPECT_EQ(heals, 0);
}

TEST(SeamRounds, CandidatesLimitTheSearchAndPlanTheSameRound) {
  // Later rounds look only at the tets the previous one left: given any superset of the star
  // tets, the plan is the one a scan of every tet makes.
  const TetMesh mesh = two_groups_meeting();
  const std::vector<int> group = groups({{100, 0}, {101, 0}, {104, 1}, {105, 1}});
  const SeamRound scanned = plan_seam_round(mesh, kFirst, group);
  const std::vector<std::int32_t> superset{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  const SeamRound limited = plan_seam_round(mesh, kFirst, group, &superset);
  EXPECT_EQ(limited.star_tets, scanned.star_tets);
  EXPECT_EQ(limited.heals, scanned.heals);
  // A star tet left out of the candidates is not seen: 105's tets are 10 and 11.
  const std::vector<std::int32_t> without_105{0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
  const SeamRound partial = plan_seam_round(mesh, kFirst, group, &without_105);
  EXPECT_EQ(partial.star_tets, (std::vector<std::int32_t>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
  EXPECT_EQ(partial.heals[105 - kFirst], 0);
}

}  // namespace
}  // namespace partet
