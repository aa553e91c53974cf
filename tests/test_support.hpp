// Helpers shared by the unit tests.
#pragma once
#include <gtest/gtest.h>

#include <atomic>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "partet/mesh_types.hpp"

namespace partet::test {

// A fresh empty directory under the build tree's temp area, removed at exit of the process.
std::string temp_dir(const std::string& name);

// Success when text contains part; the failure message shows both.
::testing::AssertionResult contains(const std::string& text, const std::string& part);

// The message of the InputError that action throws, or "(no InputError thrown)".
std::string input_error(const std::function<void()>& action);

// A tight ulimit -v, for a forked child: lowers the address-space limit to what the process maps
// now plus room_mb, then keeps busy every thread that can still start (their stacks may be cached
// from earlier tests), so that no further thread can, until it goes. ok(): both held.
class NoRoomForThreads {
 public:
  explicit NoRoomForThreads(double room_mb);
  ~NoRoomForThreads();
  bool ok() const { return ok_; }

 private:
  bool ok_ = false;
  std::atomic<bool> release_{false};
  std::vector<std::thread> holders_;
};

// The same points, tets and neighbours, in the same order.
inline void expect_same_tet_mesh(const TetMesh& a, const TetMesh& b) {
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.tets, b.tets);
  EXPECT_EQ(a.neighbours, b.neighbours);
}

}  // namespace partet::test
