// Writing large text files fast (internal header).
#pragma once
#include <charconv>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace partet {

// Formats numbers straight into a large buffer: meshes have tens of millions of numbers, so
// per-number stream or printf overhead dominates otherwise. A full buffer goes to a thread that
// writes it while the next one is formatted (the kernel's copy into the page cache costs as much
// as the formatting), and asks the kernel to start writing it to the disk (so the fsync before
// the files are published finds little left to do).
class BufferedFile {
 public:
  // Errors name `shown` (the file the user asked for), not the temporary path written.
  explicit BufferedFile(std::string path, std::string shown = "");
  ~BufferedFile();
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
  void bytes(const void* p, std::size_t n);
  void space() { put(' '); }
  void newline() { put('\n'); }

  // Writes what is left and closes the file; throws OutputError if any write failed.
  void close();
  // Returns at once: the writing thread finishes the file (so the next file is formatted
  // meanwhile, and its writes, to another inode, go on beside these). finish_background_writes
  // waits for it and reports its failure.
  void close_in_background();

  struct Writer;  // the file and its writing thread (buffered_file.cpp)

 private:
  static constexpr std::size_t kBufferSize = std::size_t(4) << 20;
  static constexpr std::size_t kMaxItem = 64;  // longer than any number or header we format

  char* data() { return buffer_.data(); }
  void put(char c) {
    reserve();
    buffer_[used_++] = c;
  }
  void reserve() {
    if (buffer_.size() - used_ < kMaxItem) flush();
  }
  void flush();  // hands the buffer to the writing thread
  [[noreturn]] void fail(int error);

  std::string shown_;
  std::vector<char> buffer_;
  std::size_t used_ = 0;
  std::unique_ptr<Writer> writer_;
};

// Waits for every file closed in the background; throws OutputError naming the first that
// failed (after all have ended).
void finish_background_writes();
// The same, ignoring failures (the files are being discarded).
void abandon_background_writes() noexcept;

}  // namespace partet
