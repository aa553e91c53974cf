// Byte encoding of what crosses a process or rank boundary: pieces, piece results and meshing
// failures (Boost.Serialization binary archives, flat arrays as single blocks).
#pragma once
#include <cstddef>
#include <string>
#include <string_view>

#include "partet/errors.hpp"
#include "partet/mesh_types.hpp"
#include "stages/piece.hpp"
#include "mesher/tetgen_mesher.hpp"

namespace partet {

// A piece and the TetGen options to mesh it with, as a worker receives it.
std::string serialize_task(const PieceSurface& piece, const TetgenOptions& tetgen);
PieceSurface deserialize_task(std::string_view bytes, TetgenOptions& tetgen);

// A meshing run's reply: one tag byte ('R' result, 'F' failure), the seconds and memory it took,
// then the result or failure. (A piece travels as a task, a result or failure as an outcome:
// there is no other form.)
std::string serialize_outcome(const PieceOutcome& outcome);
// Throws InternalError on bytes that are no reply.
PieceOutcome deserialize_outcome(std::string_view bytes);

}  // namespace partet
