// Hashable keys for triangles independent of vertex order, used to match faces between tets,
// pieces and input surfaces.
#pragma once
#include <algorithm>
#include <cstdint>
#include <functional>

#include "partet/mesh_types.hpp"

namespace partet {

struct FaceKey {
  std::int32_t v[3];
  explicit FaceKey(const Triangle& t) : v{t[0], t[1], t[2]} {
    if (v[0] > v[1]) std::swap(v[0], v[1]);
    if (v[1] > v[2]) std::swap(v[1], v[2]);
    if (v[0] > v[1]) std::swap(v[0], v[1]);
  }
  bool operator==(const FaceKey& o) const { return v[0] == o.v[0] && v[1] == o.v[1] && v[2] == o.v[2]; }
  bool operator<(const FaceKey& o) const {
    return std::lexicographical_compare(v, v + 3, o.v, o.v + 3);
  }
};

struct FaceKeyHash {
  std::size_t operator()(const FaceKey& k) const {
    std::uint64_t h = static_cast<std::uint32_t>(k.v[0]);
    h = h * 0x9E3779B97F4A7C15ull + static_cast<std::uint32_t>(k.v[1]);
    h = h * 0x9E3779B97F4A7C15ull + static_cast<std::uint32_t>(k.v[2]);
    h ^= h >> 31;
    h *= 0xBF58476D1CE4E5B9ull;
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};

// True when a and b are the same triangle with the same orientation (up to rotation).
inline bool same_orientation(const Triangle& a, const Triangle& b) {
  for (int r = 0; r < 3; ++r)
    if (a[0] == b[r] && a[1] == b[(r + 1) % 3] && a[2] == b[(r + 2) % 3]) return true;
  return false;
}

}  // namespace partet
