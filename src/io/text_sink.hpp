// Formatting text into a string exactly as BufferedFile formats it into a file (internal header):
// a rank that formats rows to send them writes the bytes rank 0 would have written.
#pragma once
#include <charconv>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>

namespace partet {

// Formats numbers at the end of a string, like BufferedFile into its buffer, so both write
// the same text from one formatter: into a buffer of its own first,
// appended in large blocks (growing the string number by number is twice as slow).
class TextSink {
 public:
  explicit TextSink(std::string& text) : text_(text), buffer_(new char[kBufferSize]) {}
  TextSink(const TextSink&) = delete;
  TextSink& operator=(const TextSink&) = delete;
  void integer(std::int64_t value) {
    reserve();
    used_ = static_cast<std::size_t>(std::to_chars(end(), limit(), value).ptr - buffer_.get());
  }
  void real(double value) {
    reserve();
    used_ = static_cast<std::size_t>(std::to_chars(end(), limit(), value, std::chars_format::general, 17).ptr -
                                     buffer_.get());
  }
  void text(std::string_view s) {  // row tails: a few characters
    reserve();
    std::memcpy(end(), s.data(), s.size());
    used_ += s.size();
  }
  void bytes(const void* p, std::size_t n) { text({static_cast<const char*>(p), n}); }  // a binary number
  void space() {
    reserve();
    buffer_[used_++] = ' ';
  }
  void newline() {
    reserve();
    buffer_[used_++] = '\n';
  }
  void flush() {
    text_.append(buffer_.get(), used_);
    used_ = 0;
  }

 private:
  static constexpr std::size_t kBufferSize = std::size_t(1) << 20;
  static constexpr std::size_t kMaxItem = 64;  // longer than any number or row tail
  char* end() { return buffer_.get() + used_; }
  char* limit() { return buffer_.get() + kBufferSize; }
  void reserve() {
    if (kBufferSize - used_ < kMaxItem) flush();
  }
  std::string& text_;
  std::unique_ptr<char[]> buffer_;
  std::size_t used_ = 0;
};

}  // namespace partet
