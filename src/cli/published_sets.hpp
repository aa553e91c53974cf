// The output sets the commands read (check, info): a publish a killed run left half done at their
// prefix is completed first (internal).
#pragma once
#include <string>

#include "io/mesh_formats.hpp"

namespace partet::cli {

// Completes a publish a killed run left half done at PREFIX (a warning says so).
void settle(const std::string& prefix);

// Whether PATH's extension names `format`; `run` (if given) is then PATH without it.
bool names_format(const std::string& path, MeshFormat format, std::string* run = nullptr);

// Settles the set PATH (an MSH, VTK or MEDIT file) names: its run may have been published at PATH
// without its extension, or (an MSH partition file) at the set's prefix.
void settle_named(const std::string& path);

}  // namespace partet::cli
