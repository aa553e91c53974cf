// Writing a whole buffer to a file descriptor (internal header).
#pragma once
#include <unistd.h>

#include <cerrno>
#include <cstddef>

namespace partet {

// Writes all `size` bytes, again after EINTR and short writes. False on an error (errno says
// which) or when nothing more can be written.
inline bool write_all(int fd, const void* data, std::size_t size) {
  const auto* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace partet
