// Typed errors. Every message is one line a user can act on.
#pragma once
#include <stdexcept>
#include <string>

namespace partet {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The input file cannot be read or is not a valid closed surface.
struct InputError : Error {
  using Error::Error;
};

// A command-line option has a value that cannot be used.
struct OptionError : Error {
  using Error::Error;
};

// Partitioning or surface closure could not produce valid pieces.
struct PartitionError : Error {
  using Error::Error;
};

// TetGen failed on a piece or changed its boundary.
struct MeshingError : Error {
  MeshingError(int piece, const std::string& what)
      : Error(piece >= 0 ? "piece " + std::to_string(piece) + ": " + what : what), piece(piece) {}
  int piece;
};

// Writing or reading result files failed.
struct OutputError : Error {
  using Error::Error;
};

}  // namespace partet
