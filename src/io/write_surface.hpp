// Writing triangle surfaces.
#pragma once
#include <string>

#include "partet/mesh_types.hpp"

namespace partet {

// Writes an ASCII OFF with coordinates that read back bit-identical. Throws OutputError.
void write_off(const SurfaceMesh& surface, const std::string& path);

}  // namespace partet
