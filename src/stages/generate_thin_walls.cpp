// CAD-like parts with thin parallel walls close together: a comb-shaped profile extruded, each
// flat face triangulated the way CAD programs export it (vertices only at corners, long thin
// triangles fanned across the faces).
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "partet/errors.hpp"
#include "stages/generate.hpp"

namespace partet {
namespace {

struct Profile {
  double base, height, depth;  // of the spine the walls stand on, of the walls, of the extrusion
};

Profile profile_of(const std::string& kind) {
  if (kind == "fins") return {3, 20, 40};    // a heat sink: fins on a base plate
  if (kind == "comb") return {2, 40, 4};     // long thin teeth on a thin spine
  if (kind == "slots") return {10, 8, 30};   // a block with slots cut into its top
  if (kind == "plates") return {3, 30, 30};  // plates stacked on a spine (walls along z)
  throw OptionError("unknown thin-wall part '" + kind + "' (known: fins, comb, slots, plates)");
}

// The comb's outline, counter-clockwise: the spine [0, W] x [0, B], walls [x_i, x_i + t] x [B, B + H].
std::vector<std::array<double, 2>> comb_outline(const ThinWallPart& part, const Profile& p, std::vector<double>& tops) {
  const double margin = part.gap;
  const double width = 2 * margin + part.walls * part.wall + (part.walls - 1) * part.gap;
  std::vector<std::array<double, 2>> outline{{0, 0}, {width, 0}, {width, p.base}};
  for (int i = part.walls - 1; i >= 0; --i) {
    const double x0 = margin + i * (part.wall + part.gap), x1 = x0 + part.wall;
    outline.push_back({x1, p.base});
    outline.push_back({x1, p.base + p.height});
    outline.push_back({x0, p.base + p.height});
    outline.push_back({x0, p.base});
    tops.push_back(x1);
    tops.push_back(x0);
  }
  outline.push_back({0, p.base});
  return outline;
}

}  // namespace

std::vector<std::string> thin_wall_kinds() { return {"fins", "comb", "slots", "plates"}; }

SurfaceMesh generate_thin_walls(const ThinWallPart& part) {
  if (part.walls < 1 || !(part.wall > 0) || !(part.gap > 0) || !std::isfinite(part.wall) || !std::isfinite(part.gap) ||
      !std::isfinite(part.turn_degrees))
    throw OptionError("a thin-wall part needs at least one wall and a positive, finite thickness and gap");
  const Profile p = profile_of(part.kind);
  std::vector<double> tops;
  const auto outline = comb_outline(part, p, tops);
  const auto n = static_cast<std::int32_t>(outline.size());
  // The profile's triangles (indices into outline): the spine fanned from its corner (0, 0) to
  // every vertex of its top edge, as CAD exports a face with many vertices on one side; each wall
  // two triangles.
  std::vector<Triangle> profile{{0, 1, 2}};
  // Spine top vertices from right to left: outline index 2, then each wall's (x1, B) and (x0, B),
  // then (0, B) last.
  std::vector<std::int32_t> top{2};
  for (int i = 0; i < part.walls; ++i) top.push_back(3 + 4 * i), top.push_back(3 + 4 * i + 3);
  top.push_back(n - 1);
  for (std::size_t k = 0; k + 1 < top.size(); ++k) profile.push_back({0, top[k], top[k + 1]});
  for (int i = 0; i < part.walls; ++i) {
    const std::int32_t a = 3 + 4 * i;  // (x1, B), (x1, B + H), (x0, B + H), (x0, B)
    profile.push_back({a, a + 1, a + 2});
    profile.push_back({a, a + 2, a + 3});
  }
  // Extrude: the profile at depth 0 (facing down) and at `depth` (facing up), a quad per edge.
  const double turn = part.turn_degrees * 3.14159265358979323846 / 180, c = std::cos(turn), s = std::sin(turn);
  SurfaceMesh surface;
  for (double z : {0.0, p.depth})
    for (const auto& q : outline) {
      const double x = c * q[0] - s * q[1], y = s * q[0] + c * q[1];
      surface.points.push_back(part.kind == "plates" ? Point3{x, z, y} : Point3{x, y, z});
    }
  const bool mirrored = part.kind == "plates";  // (x, z, y) swaps handedness
  auto add = [&](std::int32_t a, std::int32_t b, std::int32_t d) {
    surface.triangles.push_back(mirrored ? Triangle{a, d, b} : Triangle{a, b, d});
  };
  for (const Triangle& t : profile) {
    add(t[0] + n, t[1] + n, t[2] + n);
    add(t[0], t[2], t[1]);
  }
  for (std::int32_t i = 0; i < n; ++i) {
    const std::int32_t j = (i + 1) % n;
    add(i, j, j + n);
    add(i, j + n, i + n);
  }
  return surface;
}

}  // namespace partet
