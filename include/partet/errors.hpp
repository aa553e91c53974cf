// Typed errors. Every message is one line a user can act on; errors about meshing carry what
// failed, where, and which cut planes were involved, so that retry decisions never parse text.
#pragma once
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace partet {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The input file cannot be read or is not a valid closed surface.
struct InputError : Error {
  using Error::Error;
};

// An option has a value that cannot be used.
struct OptionError : Error {
  using Error::Error;
};

// Writing or reading result files failed.
struct OutputError : Error {
  using Error::Error;
};

// A bug: an invariant partet relies on does not hold. Never the user's fault.
struct InternalError : Error {
  explicit InternalError(const std::string& what) : Error("internal error: " + what) {}
};

// What went wrong while meshing a piece (or a region around cut vertices).
enum class FailureKind : std::int32_t {
  tetgen_error = 0,       // TetGen stopped with an error code
  self_intersection = 1,  // the surface given to TetGen intersects itself
  changed_boundary = 2,   // TetGen's result does not have exactly the given boundary
  bad_surface = 3,        // the surface is not closed, manifold and oriented
  crashed = 4,            // the meshing process died from a signal
  timed_out = 5,          // the meshing process used its CPU time (or 4 x that in wall time)
  no_result = 6,          // the meshing process ended without a result
  injected = 7,           // a test hook (PARTET_INJECT_FAILURE)
  other = 8,              // any other error inside the meshing process
  too_close = 9,          // TetGen took features closer than its tolerance for one (thin solids)
  runaway = 10,           // TetGen's refinement grew far past what the surface needs (a bound too tight)
  killed = 11,            // the meshing process was killed from outside (SIGKILL), most often for memory
  out_of_memory = 12,     // the meshing process ran out of memory under a limit it inherited (ulimit -v)
};

// A meshing failure as a value: it crosses process and rank boundaries serialized.
struct Failure {
  Failure() = default;
  Failure(FailureKind k, std::int32_t p, std::vector<int> involved_planes, std::string text,
          std::vector<std::int32_t> involved_faces = {})
      : kind(k), piece(p), planes(std::move(involved_planes)), message(std::move(text)), faces(std::move(involved_faces)) {}

  FailureKind kind = FailureKind::other;
  std::int32_t piece = -1;  // -1: not about one piece
  std::vector<int> planes;  // cut planes involved, when known (moving them is the remedy)
  std::string message;      // without the "piece N: " prefix
  std::vector<std::int32_t> faces;  // the piece's triangles involved (local indices), when known

  // "piece N: message" (or the message alone).
  std::string text() const { return piece >= 0 ? "piece " + std::to_string(piece) + ": " + message : message; }
};

struct MeshingError : Error {
  explicit MeshingError(Failure f) : Error(f.text()), failure(std::move(f)) {}
  MeshingError(FailureKind kind, int piece, const std::string& message, std::vector<int> planes = {})
      : MeshingError(Failure{kind, piece, std::move(planes), message}) {}
  Failure failure;
};

// No partition can help: TetGen fails on the input itself (as one piece, as TetGen alone), or the
// quality bound asked for cannot be met. The message says which.
struct InputMeshingError : MeshingError {
  // split_faces_may_help: TetGen failed because it keeps every input triangle whole (-Y); allowing
  // it points on the surface (MeshOptions::allow_split_faces) may give a mesh.
  explicit InputMeshingError(Failure f, bool split_faces_may_help = false)
      : MeshingError(std::move(f)), split_faces_may_help(split_faces_may_help) {}
  bool split_faces_may_help = false;
};

// Partitioning or surface closure could not produce valid pieces.
struct PartitionError : MeshingError {
  using MeshingError::MeshingError;
};

}  // namespace partet
