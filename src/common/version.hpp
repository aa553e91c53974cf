// Versions of partet's libraries, for --version and the report.
#pragma once
#include <string>

namespace partet {

std::string cgal_version();  // "5.5.1"

}  // namespace partet
