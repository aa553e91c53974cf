#include "stages/input_share.hpp"

#include <algorithm>
#include <cmath>

#include "partet/errors.hpp"
#include "stages/geometry.hpp"

namespace partet {

void FirstProblem::add(std::int64_t at, std::int64_t a, std::int64_t b, std::int64_t c, std::int64_t d) {
  ++count;
  if (at < order) order = at, names[0] = a, names[1] = b, names[2] = c, names[3] = d;
}

void FirstProblem::merge(const FirstProblem& other) {
  count += other.count;
  if (other.order < order) {
    order = other.order;
    std::copy(std::begin(other.names), std::end(other.names), std::begin(names));
  }
}

void InputFindings::merge(const InputFindings& share) {
  if (share.duplicate.order < duplicate.order) duplicate_at = share.duplicate_at;
  for (auto kind : {&InputFindings::repeated, &InputFindings::collinear, &InputFindings::duplicate,
                    &InputFindings::border, &InputFindings::crowded, &InputFindings::misoriented,
                    &InputFindings::split})
    (this->*kind).merge(share.*kind);
  six_volume += share.six_volume;
}

namespace {

std::string str(long long n) { return std::to_string(n); }
std::string plural(long long n, const char* word, const char* words) { return n == 1 ? word : words; }
// " (n such things)" when there are more than one.
std::string how_many(const FirstProblem& p, const char* things) {
  return p.count > 1 ? " (" + str(p.count) + " " + things + ")" : "";
}

}  // namespace

void throw_first_problem(const InputFindings& f, const std::string& subject) {
  const std::string degenerate = subject + " has a degenerate face: face ";
  if (f.repeated.count > 0)
    throw InputError(degenerate + str(f.repeated.order) + " repeats vertex " + str(f.repeated.names[0]));
  if (f.collinear.count > 0) throw InputError(degenerate + str(f.collinear.order) + " has collinear corners");
  if (f.duplicate.count > 0)
    throw InputError(subject + " has duplicate vertices: vertices " + str(f.duplicate.names[0]) + " and " +
                     str(f.duplicate.order) + " are both at " + coordinates_text(f.duplicate_at) +
                     how_many(f.duplicate, "duplicates"));
  if (f.border.count > 0)
    throw InputError(subject + " is not closed: " + str(f.border.count) + plural(f.border.count, " border edge", " border edges") +
                     ", first at vertex " + str(f.border.names[0]));
  if (f.crowded.count > 0)
    throw InputError(subject + " is not manifold: " + str(f.crowded.count) + plural(f.crowded.count, " edge", " edges") +
                     " shared by more than two faces, first between vertices " + str(f.crowded.names[0]) + " and " +
                     str(f.crowded.names[1]));
  if (f.misoriented.count > 0)
    throw InputError(subject + " is not consistently oriented: faces " + str(f.misoriented.names[0]) + " and " +
                     str(f.misoriented.names[1]) + " traverse the edge between vertices " +
                     str(f.misoriented.names[2]) + " and " + str(f.misoriented.names[3]) + " in the same direction" +
                     how_many(f.misoriented, "such edges"));
  if (f.split.count > 0)
    throw InputError(subject + " is not manifold: vertex " + str(f.split.order) + " joins " + str(f.split.names[0]) +
                     " separate fans of faces" + how_many(f.split, "such vertices"));
}

std::vector<std::uint16_t> vertex_shares(const std::vector<Point3>& points, int shares) {
  std::vector<std::uint16_t> share(points.size(), 0);
  if (shares <= 1 || points.empty()) return share;
  // The longest axis of the finite points' box (unused vertices may be anything; they go anywhere).
  Point3 low{HUGE_VAL, HUGE_VAL, HUGE_VAL}, high{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (const Point3& p : points)
    if (std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))
      for (int i = 0; i < 3; ++i) low[i] = std::min(low[i], p[i]), high[i] = std::max(high[i], p[i]);
  int axis = 0;
  for (int i = 1; i < 3; ++i)
    if (high[i] - low[i] > high[axis] - low[axis]) axis = i;
  // Cuts at quantiles of a sample: a far outlier does not unbalance them as it would a histogram.
  const std::size_t stride = std::max<std::size_t>(1, points.size() / 65536);
  std::vector<double> sample;
  for (std::size_t v = 0; v < points.size(); v += stride)
    if (std::isfinite(points[v][axis])) sample.push_back(points[v][axis]);
  if (sample.empty()) return share;
  std::sort(sample.begin(), sample.end());
  std::vector<double> cuts;
  for (int s = 1; s < shares; ++s) cuts.push_back(sample[sample.size() * static_cast<std::size_t>(s) / shares]);
  for (std::size_t v = 0; v < points.size(); ++v) {
    const double x = points[v][axis];
    if (std::isfinite(x)) share[v] = static_cast<std::uint16_t>(std::upper_bound(cuts.begin(), cuts.end(), x) - cuts.begin());
  }
  return share;
}

InputShareBuilder::InputShareBuilder(int share, int shares, std::size_t vertex_count, std::size_t face_count)
    : share_(share),
      shares_(shares),
      vertex_count_(vertex_count),
      face_count_(face_count),
      used_((vertex_count + 63) / 64, 0),
      needed_(shares > 1 ? (vertex_count + 63) / 64 : 0, 0) {
  if (shares_ == 1) return;
  // Room for a little more than an even share, so that growing rarely copies.
  owner_.reserve(vertex_count);
  const auto room = [&](std::size_t n) { return n / static_cast<std::size_t>(shares) * 9 / 8 + 1024; };
  share_data_.faces.reserve(room(face_count));
  share_data_.numbering.face_ids.reserve(room(face_count));
  share_data_.points.reserve(room(vertex_count));
  share_data_.numbering.vertex_ids.reserve(room(vertex_count));
  share_data_.numbering.owned.reserve(room(vertex_count));
}

void InputShareBuilder::add_vertex_shares(const std::uint16_t* values, std::size_t count) {
  if (shares_ > 1) owner_.insert(owner_.end(), values, values + count);
  owners_in_ += count;
}

// The indices are valid: validate_indices ran on the whole input before it was streamed.
void InputShareBuilder::add_faces(const Triangle* faces, std::size_t count) {
  InputShare& s = share_data_;
  for (std::size_t i = 0; i < count; ++i) {
    const Triangle& t = faces[i];
    for (std::int32_t v : t) set(used_, static_cast<std::size_t>(v));
    if (shares_ == 1) continue;
    if (!mine(t[0]) && !mine(t[1]) && !mine(t[2])) continue;
    s.faces.push_back(t);
    s.numbering.face_ids.push_back(static_cast<std::int32_t>(faces_in_ + i));
    for (std::int32_t v : t) set(needed_, static_cast<std::size_t>(v));
  }
  if (shares_ == 1) s.faces.insert(s.faces.end(), faces, faces + count);
  faces_in_ += count;
}

void InputShareBuilder::add_points(const Point3* points, std::size_t count) {
  InputShare& s = share_data_;
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t v = points_in_ + i;
    const Point3& p = points[i];
    if (bit(used_, v)) {
      if (!any_used_) s.numbering.box_low = s.numbering.box_high = p, any_used_ = true;
      for (int k = 0; k < 3; ++k) {
        s.numbering.box_low[k] = std::min(s.numbering.box_low[k], p[k]);
        s.numbering.box_high[k] = std::max(s.numbering.box_high[k], p[k]);
      }
    }
    if (shares_ > 1 && bit(needed_, v)) {
      s.points.push_back(p);
      s.numbering.vertex_ids.push_back(static_cast<std::int32_t>(v));
      s.numbering.owned.push_back(owner_[v] == share_ ? 1 : 0);
    }
  }
  if (shares_ == 1) s.points.insert(s.points.end(), points, points + count);
  points_in_ += count;
}

InputShare InputShareBuilder::finish() {
  if (owners_in_ != vertex_count_ || faces_in_ != face_count_ || points_in_ != vertex_count_)
    throw Error("the input check received " + std::to_string(faces_in_) + " of " + std::to_string(face_count_) +
                " faces and " + std::to_string(points_in_) + " of " + std::to_string(vertex_count_) + " points");
  std::vector<std::uint16_t>().swap(owner_);
  if (shares_ > 1) {
    // Input index -> local index: the needed vertices below it, counted by words of bits.
    std::vector<std::uint32_t> before(needed_.size(), 0);
    for (std::size_t w = 1; w < needed_.size(); ++w)
      before[w] = before[w - 1] + static_cast<std::uint32_t>(__builtin_popcountll(needed_[w - 1]));
    auto local = [&](std::int32_t v) {
      const auto i = static_cast<std::size_t>(v);
      const std::uint64_t below = needed_[i >> 6] & ((std::uint64_t{1} << (i & 63)) - 1);
      return static_cast<std::int32_t>(before[i >> 6] + static_cast<std::uint32_t>(__builtin_popcountll(below)));
    };
    for (Triangle& t : share_data_.faces)
      for (std::int32_t& v : t) v = local(v);
  }
  std::vector<std::uint64_t>().swap(used_);
  std::vector<std::uint64_t>().swap(needed_);
  return std::move(share_data_);
}

}  // namespace partet
