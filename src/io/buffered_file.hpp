// Writing large text files fast (internal header).
#pragma once
#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "partet/errors.hpp"

namespace partet {

// Formats numbers straight into a large buffer and hands it to fwrite in big blocks: meshes
// have tens of millions of numbers, so per-number stream or printf overhead dominates otherwise.
class BufferedFile {
 public:
  // Errors name `shown` (the file the user asked for), not the temporary path written.
  explicit BufferedFile(std::string path, std::string shown = "")
      : path_(std::move(path)), shown_(shown.empty() ? path_ : std::move(shown)), buffer_(kBufferSize) {
    file_ = std::fopen(path_.c_str(), "wb");
    if (!file_) fail();
  }
  ~BufferedFile() {
    if (file_) std::fclose(file_);
  }
  BufferedFile(const BufferedFile&) = delete;
  BufferedFile& operator=(const BufferedFile&) = delete;

  void integer(std::int64_t value) {
    reserve();
    used_ = std::to_chars(data() + used_, data() + buffer_.size(), value).ptr - data();
  }
  // Same text as printf("%.17g"): 17 significant digits always read back to the same double.
  void real(double value) {
    reserve();
    used_ = std::to_chars(data() + used_, data() + buffer_.size(), value, std::chars_format::general, 17).ptr - data();
  }
  void text(std::string_view s) { bytes(s.data(), s.size()); }
  // Any length: small runs go through the buffer, large ones straight to the file.
  void bytes(const void* p, std::size_t n) {
    if (buffer_.size() - used_ < n) flush();
    if (n >= buffer_.size()) {
      if (std::fwrite(p, 1, n, file_) != n) fail();
      return;
    }
    std::memcpy(data() + used_, p, n);
    used_ += n;
  }
  void space() { put(' '); }
  void newline() { put('\n'); }

  void close() {
    flush();
    std::FILE* f = file_;
    file_ = nullptr;
    if (std::fclose(f) != 0) fail();
  }

 private:
  static constexpr std::size_t kBufferSize = std::size_t(1) << 20;
  static constexpr std::size_t kMaxItem = 64;  // longer than any number or header we format

  char* data() { return buffer_.data(); }
  void put(char c) {
    reserve();
    buffer_[used_++] = c;
  }
  void reserve() {
    if (buffer_.size() - used_ < kMaxItem) flush();
  }
  void flush() {
    if (used_ > 0 && std::fwrite(data(), 1, used_, file_) != used_) fail();
    used_ = 0;
  }
  [[noreturn]] void fail() { throw OutputError("cannot write '" + shown_ + "': " + std::strerror(errno)); }

  std::string path_, shown_;
  std::vector<char> buffer_;
  std::size_t used_ = 0;
  std::FILE* file_ = nullptr;
};

}  // namespace partet
