// Byte encoding of the messages the MPI layer moves (Boost.Serialization binary archives).
#pragma once
#include <string>

#include "partet/piece.hpp"
#include "partet/tetgen_mesher.hpp"

namespace partet {

std::string serialize_piece(const PieceSurface& piece);
PieceSurface deserialize_piece(const std::string& bytes);

std::string serialize_result(const PieceTetMesh& result);
PieceTetMesh deserialize_result(const std::string& bytes);

}  // namespace partet
