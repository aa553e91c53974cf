// The input's checks split into shares, so that an input too large for one rank can be checked
// by several, each holding a compact part of it (internal header). Share s owns the vertices
// vertex_shares() gives it; it checks their edges and fans, the duplicates among them, and the
// faces whose lowest vertex it owns. The shares' findings combine into the verdict one process
// checking the whole input gives: every problem is found by exactly one share, and each kind
// keeps its first in the order of the whole input's check.
#pragma once
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "partet/mesh_types.hpp"

namespace partet {

// A share's own numbering: its local vertices and faces in the whole input's order, so that
// "lower vertex" and "first face" mean the same locally and globally.
struct ShareNumbering {
  std::vector<std::int32_t> vertex_ids;  // input index of each local vertex; empty: the identity
  std::vector<std::int32_t> face_ids;    // input index of each local face; empty: the identity
  std::vector<char> owned;               // per local vertex; empty: the share owns every vertex
  Point3 box_low{}, box_high{};          // the used vertices' box (volume terms are measured from its centre)
  std::int32_t vertex_id(std::int32_t v) const { return vertex_ids.empty() ? v : vertex_ids[v]; }
  std::int64_t face_id(std::size_t f) const {
    return face_ids.empty() ? static_cast<std::int64_t>(f) : face_ids[f];
  }
  bool owns(std::int32_t v) const { return owned.empty() || owned[v] != 0; }
};

// One share of an input: the points of its owned vertices and of their neighbours, and every
// face around an owned vertex, in local numbering.
struct InputShare {
  std::vector<Point3> points;
  std::vector<Triangle> faces;
  ShareNumbering numbering;
};

// The first of a kind of problem, by `order` (a face, corner or vertex of the input), with what
// its message names, and how many there are.
struct FirstProblem {
  std::int64_t count = 0;
  std::int64_t order = std::numeric_limits<std::int64_t>::max();
  std::int64_t names[4] = {-1, -1, -1, -1};
  void add(std::int64_t at, std::int64_t a = -1, std::int64_t b = -1, std::int64_t c = -1, std::int64_t d = -1);
  void merge(const FirstProblem& other);
};

// What the checks of a share (or of the whole input) found. Trivially copyable: ranks send it
// as bytes.
struct InputFindings {
  FirstProblem repeated;     // faces repeating a vertex: order face; names the vertex
  FirstProblem collinear;    // faces with collinear corners: order face
  FirstProblem duplicate;    // used vertices at one position: order the later vertex; names the earlier
  Point3 duplicate_at{};     // the position of the first duplicate
  FirstProblem border;       // edges used once: order corner (3 face + c); names the corner's vertex
  FirstProblem crowded;      // edges used more than twice: order corner; names the edge's two vertices
  FirstProblem misoriented;  // edges used twice in one direction: order corner; names the faces, the vertices
  FirstProblem split;        // vertices joining several fans: order vertex; names the fan count
  long double six_volume = 0;  // six times the enclosed volume, from the used vertices' box centre
  void merge(const InputFindings& share);  // `share` is the next share in order
};

// Throws InputError for the first problem of the whole input's check order (degenerate faces,
// duplicate vertices, edges, fans), naming `subject` ("input is not closed: ..."). Returns if none.
void throw_first_problem(const InputFindings& findings, const std::string& subject);

// The share of each vertex among `shares`: slabs along the longest axis of the points' box, cut
// at quantiles of a sample of them, so each share is a compact part of the surface (few faces
// cross between shares) and vertices at one position share a share.
std::vector<std::uint16_t> vertex_shares(const std::vector<Point3>& points, int shares);

// Builds share `share` from the whole input streamed in parts, in order: the vertex shares,
// then the faces, then the points. Holds its share, a bit per input vertex, and 2 bytes per
// input vertex until the points come.
class InputShareBuilder {
 public:
  InputShareBuilder(int share, int shares, std::size_t vertex_count, std::size_t face_count);
  void add_vertex_shares(const std::uint16_t* values, std::size_t count);
  void add_faces(const Triangle* faces, std::size_t count);
  void add_points(const Point3* points, std::size_t count);
  InputShare finish();  // after every part has come

 private:
  bool mine(std::int32_t v) const { return owner_[static_cast<std::size_t>(v)] == share_; }  // with several shares
  static bool bit(const std::vector<std::uint64_t>& bits, std::size_t i) { return (bits[i >> 6] >> (i & 63)) & 1; }
  static void set(std::vector<std::uint64_t>& bits, std::size_t i) { bits[i >> 6] |= std::uint64_t{1} << (i & 63); }

  int share_, shares_;
  std::size_t vertex_count_, face_count_;
  std::size_t owners_in_ = 0, faces_in_ = 0, points_in_ = 0;
  std::vector<std::uint16_t> owner_;      // until the points come
  std::vector<std::uint64_t> used_, needed_;  // a bit per input vertex
  bool any_used_ = false;
  InputShare share_data_;  // faces in input numbering until finish()
};

}  // namespace partet
