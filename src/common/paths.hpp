// Paths (internal header).
#pragma once
#include <string>

namespace partet {

// path from the working directory's absolute name, as the kernel would resolve it (no ".."
// folded); path as it is when it is absolute, or when the working directory cannot be named.
std::string absolute_path(const std::string& path);

// The directory a path's file is in: its parent, "." for a bare name.
std::string directory_of(const std::string& path);

// Throws OptionError ("OPTION: 'DIR' is not a directory", "OPTION: cannot write in 'DIR' (why)")
// unless DIR is a directory this process may write in.
void check_writable_directory(const std::string& option, const std::string& directory);

}  // namespace partet
