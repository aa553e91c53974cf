#include "stages/seam_band.hpp"

#include <algorithm>
#include <string>

#include "partet/errors.hpp"

namespace partet {

BandMarks::BandMarks(const std::vector<Tet>& tets, const std::vector<Tet>& neighbours, const BandSpec& spec)
    : neighbours_(neighbours), layers_(spec.layers), depth_(tets.size(), -1) {
  if (spec.layers < 0 || spec.layers > 100)
    throw InternalError("a seam band of " + std::to_string(spec.layers) + " layers");
  auto removed = [&](std::int32_t v) { return v >= spec.first_removed && v < spec.end_removed; };
  // On a cut plane: split points that are not input vertices (no plane passes through one).
  auto on_planes = [&](std::int32_t v) { return v >= spec.input_vertex_count && v < spec.split_point_count; };
  std::vector<std::int32_t> seeds;
  for (std::size_t t = 0; t < tets.size(); ++t) {
    const Tet& tet = tets[t];
    if (removed(tet[0]) || removed(tet[1]) || removed(tet[2]) || removed(tet[3])) {
      depth_[t] = 0;
      seeds.push_back(static_cast<std::int32_t>(t));
    }
    for (int j = 0; j < 4; ++j) {
      if (neighbours[t][j] >= 0) continue;
      const Triangle face = outward_face(tet, j);
      if (on_planes(face[0]) && on_planes(face[1]) && on_planes(face[2]))
        cap_faces_.push_back({FaceKey(face), static_cast<std::int32_t>(t)});
    }
  }
  std::sort(cap_faces_.begin(), cap_faces_.end());
  spread(std::move(seeds));
}

// Breadth first from `from` (their depths set), lowering depths where a shorter way is found.
void BandMarks::spread(std::vector<std::int32_t> from) {
  for (std::size_t i = 0; i < from.size(); ++i) {
    const std::int32_t t = from[i];
    const int next = depth_[t] + 1;
    if (next > layers_) continue;
    for (auto nb : neighbours_[t])
      if (nb >= 0 && (depth_[nb] < 0 || depth_[nb] > next)) {
        depth_[nb] = static_cast<std::int8_t>(next);
        from.push_back(nb);
      }
  }
}

std::vector<CapCrossing> BandMarks::crossings() const {
  std::vector<CapCrossing> out;
  for (const auto& face : cap_faces_) {
    const int d = depth_[face.tet];
    if (d >= 0 && d < layers_) out.push_back({face.key, d});
  }
  return out;
}

std::vector<FaceKey> BandMarks::cap_faces_outside() const {
  std::vector<FaceKey> out;
  for (const auto& face : cap_faces_)
    if (depth_[face.tet] < 0) out.push_back(face.key);
  return out;
}

bool BandMarks::enter(const std::vector<CapCrossing>& from_neighbour) {
  std::vector<std::int32_t> entered;
  for (const auto& crossing : from_neighbour) {
    const OpenCapFace probe{crossing.key, 0};
    const auto it = std::lower_bound(cap_faces_.begin(), cap_faces_.end(), probe);
    if (it == cap_faces_.end() || !(it->key == crossing.key)) continue;  // on the neighbour's other cap
    const int d = crossing.depth + 1;
    if (d > layers_ || (depth_[it->tet] >= 0 && depth_[it->tet] <= d)) continue;
    depth_[it->tet] = static_cast<std::int8_t>(d);
    entered.push_back(it->tet);
  }
  const bool grew = !entered.empty();
  spread(std::move(entered));
  return grew;
}

std::vector<std::vector<std::int8_t>> mark_bands(const std::vector<const std::vector<Tet>*>& tets,
                                                 const std::vector<const std::vector<Tet>*>& neighbours,
                                                 const BandSpec& spec) {
  std::vector<BandMarks> marks;
  marks.reserve(tets.size());
  for (std::size_t p = 0; p < tets.size(); ++p) marks.emplace_back(*tets[p], *neighbours[p], spec);
  // (Where a piece is thicker than a tet, a star tet's cap face holds its removed vertex and the
  // tet across is a star tet too; a tet of a thin piece may have its cap face on one plane and its
  // removed vertex on the other.)
  for (bool grew = true; grew;) {
    grew = false;
    for (std::size_t p = 0; p < marks.size(); ++p) {
      const std::vector<CapCrossing> crossing = marks[p].crossings();
      if (p > 0) grew = marks[p - 1].enter(crossing) || grew;
      if (p + 1 < marks.size()) grew = marks[p + 1].enter(crossing) || grew;
    }
  }
  std::vector<std::vector<std::int8_t>> depths;
  depths.reserve(marks.size());
  for (auto& m : marks) depths.push_back(m.take_depth());
  return depths;
}

}  // namespace partet
