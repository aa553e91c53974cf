// How the command line starts MPI and what it learns of its launcher before that (internal).
#pragma once
#include <string>

namespace partet::cli {

// This process's rank when an MPI launcher started it; 0 without one.
int launched_rank();

// How many ranks an MPI launcher started (before MPI_Init: from its environment); 1 without one.
int launched_size();

// MPI_Init, with Open MPI's start-up trimmed for a process run alone (see launch.cpp).
void start_mpi(int& argc, char**& argv);

// A usage error: one line from the first rank, exit code 2 (see launch.cpp).
int usage_error(int argc, char** argv, const std::string& message);

// Why MPI could not make its session directory, in one line a user can act on; empty when it can.
std::string unwritable_session_directory();

}  // namespace partet::cli
