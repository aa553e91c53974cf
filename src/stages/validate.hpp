// Checks that a surface is something TetGen can mesh: closed, manifold, consistently and
// outward oriented, no degenerate faces, no self-intersections.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "partet/mesh_types.hpp"
#include "stages/input_share.hpp"

namespace partet {

// Faces refer to existing vertices with finite coordinates: what any stage needs to run at
// all on a surface (the other checks can run elsewhere meanwhile). Throws InputError.
void validate_indices(const SurfaceMesh& surface);

// Combinatorial and degeneracy checks (cheap, linear). Throws InputError naming the first
// problem and where it is, e.g. "input is not closed: 12 border edges, first at vertex 381".
void validate_topology(const SurfaceMesh& surface);

// The checks of validate_topology (and the enclosed volume) on one share of an input
// (input_share.hpp), or on the whole input as one share; the indices must be valid
// (validate_indices). The edges are gathered corners_per_range at a time (a bound on the
// memory; the findings do not depend on it).
InputFindings check_share(const InputShare& share);
InputFindings check_share(const std::vector<Point3>& points, const std::vector<Triangle>& faces,
                          const ShareNumbering& numbering, std::size_t corners_per_range = std::size_t(8) << 20);
InputFindings check_whole(const SurfaceMesh& surface);
// The same findings from `shares` shares of the input checked at once, a thread each (the
// volume up to rounding). Each share holds a copy of its part of the input meanwhile.
InputFindings check_whole(const SurfaceMesh& surface, int shares);

// Every undirected edge is used by exactly two faces traversing it in opposite directions, else
// InputError naming the first that is not ("subject is not closed: ..."). Returns, for each
// corner 3 f + c, the other face of the edge from corner c to c + 1 of face f. The edges are
// gathered corners_per_range at a time (a bound on the memory; the result does not depend on it).
std::vector<std::int32_t> faces_across_edges(const SurfaceMesh& surface, const std::string& subject,
                                             std::size_t corners_per_range = std::size_t(8) << 20);

// Throws InputError if two faces intersect other than in a shared edge or vertex
// ("input self-intersects: faces 12 and 873 intersect"). `what` names the surface in the message.
void check_no_self_intersections(const SurfaceMesh& surface, const char* what = "input");

// Throws InputError when the shells (closed components) are not nested consistently: a shell
// inside an even number of other shells must face outwards, inside an odd number (a cavity)
// inwards. Costs shells x faces: used to explain a failure, not on every run.
void check_shell_nesting(const SurfaceMesh& surface);

// Volume enclosed by a closed oriented surface (cavities count negative).
double enclosed_volume(const SurfaceMesh& surface);
// The same in long double, whose range does not underflow at any double input's scale.
long double enclosed_volume_precise(const SurfaceMesh& surface);

}  // namespace partet
