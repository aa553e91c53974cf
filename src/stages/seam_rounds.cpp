#include "stages/seam_rounds.hpp"

#include <algorithm>
#include <set>
#include <tuple>

namespace partet {
namespace {

// The vertices left, joined into components (sharing tets) and into single-group parts
// (sharing tets within a group).
struct Stars {
  std::vector<std::int32_t> tets;  // ascending
  DisjointSets together, alone;
  Stars(std::int32_t first, std::size_t count) : together(first, count), alone(first, count) {}
};

// Records tet t when it holds vertices left to remove, joining them.
void add_star_tet(const TetMesh& mesh, std::int32_t t, std::int32_t first, const std::vector<int>& group,
                  Stars& stars) {
  const TetRemoved found(mesh.tets[t], first, group);
  if (found.count == 0) return;
  stars.tets.push_back(t);
  for (int i = 1; i < found.count; ++i) {
    stars.together.join(found.vertex[i], found.vertex[0]);
    for (int j = 0; j < i; ++j)
      if (found.group[j] == found.group[i]) stars.alone.join(found.vertex[i], found.vertex[j]);
  }
}

// The star tets among `candidates` (all tets when null), in ascending order.
Stars find_stars(const TetMesh& mesh, std::int32_t first, const std::vector<int>& group,
                 const std::vector<std::int32_t>* candidates) {
  Stars stars(first, group.size());
  if (candidates)
    for (auto t : *candidates) add_star_tet(mesh, t, first, group, stars);
  else
    for (std::size_t t = 0; t < mesh.tets.size(); ++t)
      add_star_tet(mesh, static_cast<std::int32_t>(t), first, group, stars);
  return stars;
}

// Per component: its star tets, those of each of its groups, and the pairs of its groups that
// meet (share a tet). Each star tet counts in the component and single-group part of its first
// vertex left.
struct Components {
  std::vector<std::int32_t> of_set;      // component of each `together` set, or -1
  std::vector<std::int64_t> tets;        // by component
  std::vector<std::int64_t> group_tets;  // by component * groups + group
  std::set<std::tuple<std::int32_t, int, int>> meet;
  std::vector<int> chain;                   // by component
  std::vector<std::int64_t> largest_alone;  // by chain: star tets of its largest single-group part
};

Components measure_components(const TetMesh& mesh, std::int32_t first, const std::vector<int>& group, int groups,
                              const std::vector<int>* chain_of_group, Stars& stars) {
  Components c;
  c.of_set.assign(group.size(), -1);
  auto chain_of = [&](int g) { return chain_of_group ? (*chain_of_group)[g] : 0; };
  int chains = 1;
  if (chain_of_group)
    for (int chain : *chain_of_group) chains = std::max(chains, chain + 1);
  c.largest_alone.assign(static_cast<std::size_t>(chains), 0);
  std::vector<std::int64_t> alone_tets(group.size(), 0);
  for (auto t : stars.tets) {
    const TetRemoved found(mesh.tets[t], first, group);
    std::int32_t& component = c.of_set[stars.together.find(found.vertex[0])];
    if (component < 0) {
      component = static_cast<std::int32_t>(c.tets.size());
      c.tets.push_back(0);
      c.chain.push_back(chain_of(found.group[0]));
      c.group_tets.resize(c.group_tets.size() + static_cast<std::size_t>(groups), 0);
    }
    ++c.tets[component];
    std::int64_t& largest = c.largest_alone[chain_of(found.group[0])];
    largest = std::max(largest, ++alone_tets[stars.alone.find(found.vertex[0])]);
    int distinct[4] = {}, count = 0;
    for (int i = 0; i < found.count; ++i)
      if (std::find(distinct, distinct + count, found.group[i]) == distinct + count) distinct[count++] = found.group[i];
    for (int i = 0; i < count; ++i) {
      ++c.group_tets[static_cast<std::size_t>(component) * groups + distinct[i]];
      for (int j = i + 1; j < count; ++j)
        c.meet.emplace(component, std::min(distinct[i], distinct[j]), std::max(distinct[i], distinct[j]));
    }
  }
  return c;
}

// By component * groups + group: whether that group's vertices of the component heal now.
std::vector<char> groups_taken(const Components& c, int groups) {
  std::vector<char> takes(c.group_tets.size(), 0);
  for (std::size_t component = 0; component < c.tets.size(); ++component) {
    const std::int64_t* tets = &c.group_tets[component * groups];
    char* taken = &takes[component * groups];
    std::vector<int> order;
    for (int g = 0; g < groups; ++g)
      if (tets[g] > 0) order.push_back(g);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return tets[a] > tets[b]; });
    const bool at_once = c.tets[component] <= c.largest_alone[c.chain[component]];
    for (int g : order) {
      bool meets_taken = false;
      for (int h = 0; h < groups && !at_once && !meets_taken; ++h)
        meets_taken = taken[h] && c.meet.count({static_cast<std::int32_t>(component), std::min(g, h), std::max(g, h)});
      taken[g] = !meets_taken;
    }
  }
  return takes;
}

}  // namespace

SeamRound plan_seam_round(const TetMesh& mesh, std::int32_t first, const std::vector<int>& group,
                          const std::vector<std::int32_t>* candidates, const std::vector<int>* chain_of_group) {
  int groups = 0;
  for (int g : group) groups = std::max(groups, g + 1);
  Stars stars = find_stars(mesh, first, group, candidates);
  const Components components = measure_components(mesh, first, group, groups, chain_of_group, stars);
  const std::vector<char> takes = groups_taken(components, groups);
  SeamRound round{std::vector<char>(group.size(), 0), std::move(stars.tets)};
  for (auto t : round.star_tets) {
    const TetRemoved found(mesh.tets[t], first, group);
    for (int i = 0; i < found.count; ++i) {
      const auto component = static_cast<std::size_t>(components.of_set[stars.together.find(found.vertex[i])]);
      round.heals[found.vertex[i] - first] = takes[component * groups + found.group[i]];
    }
  }
  return round;
}

}  // namespace partet
