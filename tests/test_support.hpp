// Helpers shared by the unit tests.
#pragma once
#include <gtest/gtest.h>

#include <functional>
#include <string>

namespace partet::test {

// A fresh empty directory under the build tree's temp area, removed at exit of the process.
std::string temp_dir(const std::string& name);

// Success when text contains part; the failure message shows both.
::testing::AssertionResult contains(const std::string& text, const std::string& part);

// The message of the InputError that action throws, or "(no InputError thrown)".
std::string input_error(const std::function<void()>& action);

}  // namespace partet::test
