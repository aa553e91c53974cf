// Loop subdivision: 4x the faces per step, still a closed, valid surface enclosing about the
// same volume.
#include <gtest/gtest.h>

#include <cmath>

#include "partet/errors.hpp"
#include "stages/generate.hpp"
#include "stages/refine_surface.hpp"
#include "stages/validate.hpp"
#include "stage_batches.hpp"

namespace partet {
namespace {

TEST(LoopSubdivide, FourTimesTheFacesAndStillValid) {
  const SurfaceMesh torus = generate_surface("torus", 1000);
  for (int steps : {0, 1, 2}) {
    SCOPED_TRACE("steps " + std::to_string(steps));
    const SurfaceMesh refined = loop_subdivide(torus, steps);
    EXPECT_EQ(refined.triangles.size(), torus.triangles.size() << (2 * steps));
    EXPECT_NO_THROW(validate_surface(refined));  // closed, manifold, oriented, no self-intersections
    // Loop subdivision shrinks a convex-ish shape a little, never by much.
    EXPECT_NEAR(enclosed_volume(refined), enclosed_volume(torus), 0.1 * enclosed_volume(torus));
  }
}

TEST(LoopSubdivide, DropsUnusedVerticesAndRejectsBadSurfaces) {
  SurfaceMesh sphere = generate_surface("sphere", 300);
  sphere.points.push_back({10, 10, 10});  // unreferenced
  const SurfaceMesh refined = loop_subdivide(sphere, 1);
  EXPECT_EQ(refined.triangles.size(), 4 * sphere.triangles.size());
  for (const auto& p : refined.points) EXPECT_LT(std::abs(p[0]), 2.0);
  SurfaceMesh open = generate_surface("sphere", 300);
  open.triangles.pop_back();
  EXPECT_THROW(loop_subdivide(open, 1), InputError);
  EXPECT_THROW(loop_subdivide(sphere, -1), OptionError);
}

}  // namespace
}  // namespace partet
