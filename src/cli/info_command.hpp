// partet info: what a surface or a tet mesh file holds (internal to the command line).
#pragma once
#include <string>

namespace partet::cli {

// Describes FILE: a surface, TetGen files (PREFIX, PREFIX.node or PREFIX.ele) or a tet mesh in
// another format partet writes. An XDMF set is read through MPI (started and ended here).
int run_info(int argc, char** argv, const std::string& file, bool json);

}  // namespace partet::cli
