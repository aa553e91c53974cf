// partet check: a mesh against its input surface, in this process or on every rank of a job
// (internal to the command line).
#pragma once
#include <string>

#include "stages/check.hpp"

namespace partet::cli {

// The check in this process: the whole set read, its quality printed (with the seam zone's when the
// run's --report is given). Exit code 0 when the check passes, 1 when it fails.
int run_check(const std::string& input_path, const std::string& prefix, const std::string& report_path, bool json,
              BoundaryRule rule);

// The check under MPI, each rank its part: an XDMF set, or any set under a launcher. Starts and
// ends MPI; rank 0 prints. Exit code 0 when it passes, 1 when it fails, 2 when MPI cannot start.
int run_check_on_ranks(int argc, char** argv, const std::string& input, const std::string& path, bool json);

}  // namespace partet::cli
