// A whole file's bytes, for the readers that take a file at once (MSH, MEDIT, a .pvtu index).
#pragma once
#include <fstream>
#include <string>

#include "partet/errors.hpp"

namespace partet {

// Throws InputError when the file cannot be opened or read.
inline std::string file_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw InputError("cannot open '" + path + "'");
  std::string text(static_cast<std::size_t>(in.tellg()), '\0');
  if (!in.seekg(0).read(text.data(), static_cast<std::streamsize>(text.size())))
    throw InputError("'" + path + "' cannot be read");
  return text;
}

}  // namespace partet
