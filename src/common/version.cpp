#include "common/version.hpp"

#include <CGAL/version.h>

namespace partet {

std::string cgal_version() { return CGAL_VERSION_STR; }

}  // namespace partet
