// partet's public API: fills a closed triangle surface with tetrahedra whose boundary is exactly
// the input triangles, cutting it into pieces that TetGen meshes side by side, in one process or
// across the ranks of an MPI communicator. Link partet::partet (CMake: find_package(partet)) or
// `pkg-config --cflags --libs partet`.
//
//   partet::SurfaceMesh torus = partet::generate_surface("torus", 2000);
//   partet::Options options;
//   options.pieces = 4;
//   partet::Result result = partet::tetrahedralize(torus, options);  // or (..., MPI_COMM_WORLD)
//
// Errors are exceptions derived from partet::Error (errors.hpp), each with a message a user can
// act on: InputError (not a closed, manifold, oriented surface), OptionError, MeshingError.
#pragma once
#include <mpi.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "partet/errors.hpp"
#include "partet/mesh_types.hpp"

namespace partet {

struct Options {
  int pieces = 2;       // pieces to cut the input into (1: TetGen alone); fewer when it is small
  std::string quality;  // "" (none) or TetGen's -q bound "R" or "R/ANGLE", 1 <= R, ANGLE <= 20
  // When TetGen cannot mesh the input keeping every triangle whole, accept a mesh that splits
  // some (Result::split_faces_from) instead of throwing.
  bool allow_split_faces = false;
  bool verbose = false;  // print the stages' progress (on stdout; warnings always go to stderr)
  // Non-empty: the paper's memory mode. The pieces' meshes, but for the tets around the cuts, wait
  // in files in this directory (rank 0's) until the result is assembled, instead of in memory.
  // A directory that cannot be written is an OptionError.
  std::string scratch;
  // Non-empty: every meshed piece is kept in this directory (made if missing), and a call on the
  // same surface with the same options takes the pieces it finds there instead of meshing them
  // again, so a run that was stopped loses none of them; the result is the same. An OptionError
  // when it cannot be made or written.
  std::string checkpoint;
};

struct Report {
  int pieces = 0;                       // pieces used (fewer than asked after a fallback)
  int retries = 0;                      // partitions that failed before the one used
  std::int64_t split_input_faces = 0;   // with allow_split_faces: input triangles split
  double seconds = 0;                   // wall time of the call (on rank 0)
};

struct Result {
  // Positively oriented tets; the points are the input's (those a triangle uses, in order), then
  // the Steiner points TetGen added.
  TetMesh mesh;
  // The boundary, outward, in mesh numbering: the input triangles in order; with split faces the
  // whole ones first, then the parts of the split ones from split_faces_from on.
  std::vector<Triangle> boundary_faces;
  std::size_t split_faces_from = SIZE_MAX;  // SIZE_MAX: every input triangle is whole
  Report report;
};

// Meshes in this process: the pieces one after another, each in a child process (so a TetGen
// crash becomes a MeshingError). Not from two threads at once. The first call starts a thread
// that stays, sleeping 50 ms at a time: it notices when the process was stopped (a suspended
// job), so that the pause does not count against a piece's time limit.
Result tetrahedralize(const SurfaceMesh& surface, const Options& options = {});

// Collective over comm: every rank calls it; only rank 0's surface is read (the others may pass
// an empty one). Pieces are meshed on all ranks; the result is on rank 0 (empty elsewhere). An
// error is thrown on every rank, with the same type and message.
Result tetrahedralize(const SurfaceMesh& surface, const Options& options, MPI_Comm comm);

// A surface from a file: OFF, OBJ, PLY or STL (ASCII or binary). Throws InputError.
SurfaceMesh read_surface(const std::string& path);

// A generated closed surface of about that many triangles: "sphere", "torus", "genus3",
// "nested" (a sphere with a cavity and an island), "two_spheres".
SurfaceMesh generate_surface(const std::string& shape, int faces);

// An independent check of a result against its input: tets positively oriented, faces shared
// by at most two tets, the boundary exactly the input triangles (or their parts, when split),
// the volume and Euler characteristic the input implies. Empty when valid, else what is wrong.
std::vector<std::string> check(const SurfaceMesh& surface, const Result& result);

// partet's version, e.g. "0.1.0".
std::string version();

}  // namespace partet
