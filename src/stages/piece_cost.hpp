// What a piece costs TetGen, estimated before any closure, and the cut positions that make the
// pieces cost the same.
//
// The model: a piece costs its triangles. Those are its share of the input (triangles counted by
// centroid), the fragments of the input triangles its cut planes split, and its caps. A plane
// crossed by B input edges adds about B fragments and B * (1 + 8 * density) cap triangles to each
// side (a cap's graded lattice has about 4 * density interior points per border point: see
// graded_cap_points). Measured on this machine (README, "Balancing the pieces"): without
// --quality a piece's TetGen time is linear in its triangles; with --quality its enclosed volume
// did not change the time per triangle beyond the run-to-run noise, so volume is not modelled.
#pragma once
#include <vector>

#include "partet/mesh_types.hpp"
#include "stages/partition.hpp"

namespace partet {

// Estimated triangles added to each side of a plane per input edge crossing it.
double triangles_per_crossing(double density);

// The estimated cost (triangles) of each of the planes.size() + 1 pieces.
std::vector<double> estimated_piece_costs(const SurfaceMesh& surface, const std::vector<CutPlane>& planes,
                                          double density);

// Fractions of the used vertices below each of k-1 planes perpendicular to `axis` that give
// every piece the same estimated cost (for choose_cut_planes). Empty when k < 2, or when the
// caps alone would fill a piece (then an equal split of the vertices is as good as any).
std::vector<double> cost_balanced_fractions(const SurfaceMesh& surface, const Point3& axis, int k, double density);
// The same from the vertices already sorted along the axis.
std::vector<double> cost_balanced_fractions(const SurfaceMesh& surface, const AxisVertices& along, int k,
                                            double density);

}  // namespace partet
