// Helpers shared by the unit tests.
#pragma once
#include <string>

namespace partet::test {

// A fresh empty directory under the build tree's temp area, removed at exit of the process.
std::string temp_dir(const std::string& name);

}  // namespace partet::test
