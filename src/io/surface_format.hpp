// What a surface file is and whether its header can be trusted, before and after CGAL reads it
// (internal header): the format from the extension, size guards on declared counts, and
// one-line diagnoses of malformed OFF and OBJ text.
#pragma once
#include <cstdint>
#include <optional>
#include <string>

namespace partet {

extern const char* const kSupportedFormats;  // ".off, .obj, .ply, .stl"

// "off" for "model.OFF"; empty without an extension.
std::string lowercase_extension(const std::string& path);
// "OFF" for "off".
std::string format_name(const std::string& ext);

// Throws InputError when an OFF or PLY header declares more vertices and faces than a file of
// file_size bytes can hold (CGAL reserves memory for the declared counts), when a PLY header is
// malformed (CGAL's PLY reader crashes on some), or when an .stl file is neither ASCII nor a
// binary STL of consistent size.
void check_declared_counts(const std::string& path, const std::string& ext, std::uintmax_t file_size);

// What is wrong with an ASCII OFF or OBJ file, or an empty string if the scan cannot tell.
std::string diagnose_off(const std::string& path);
std::string diagnose_obj(const std::string& path);

}  // namespace partet
