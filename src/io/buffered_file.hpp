// Writing large text files fast (internal header).
#pragma once
#include <charconv>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace partet {

// Bytes aligned for direct I/O (the page size; a device's logical block is at most that).
class AlignedBytes {
 public:
  static constexpr std::size_t kAlignment = 4096;
  explicit AlignedBytes(std::size_t size = 0);
  char* data() { return bytes_.get(); }
  const char* data() const { return bytes_.get(); }
  std::size_t size() const { return size_; }
  char& operator[](std::size_t i) { return bytes_[i]; }
  void swap(AlignedBytes& other) noexcept { bytes_.swap(other.bytes_), std::swap(size_, other.size_); }

 private:
  struct Free {
    void operator()(char* p) const noexcept;
  };
  std::unique_ptr<char[], Free> bytes_;
  std::size_t size_ = 0;
};

// Formats numbers straight into a large buffer: meshes have tens of millions of numbers, so
// per-number stream or printf overhead dominates otherwise. A full buffer goes to a thread that
// writes it while the next one is formatted.
//
// A file longer than one buffer is written around the page cache (O_DIRECT) where the
// filesystem is a local disk's (ext4, XFS, btrfs): the kernel's copy into the page cache and the
// writeback after it cost several times the disk write itself (measured: 0.23-0.30 GB/s
// buffered with fsync, 1.2-1.4 GB/s direct), and a mesh of many gigabytes does not evict
// everything else cached. Elsewhere (network and parallel filesystems, tmpfs), or when the
// filesystem refuses a direct write, the page cache is used and the kernel is asked to start
// writing each buffer to the disk (so the fsync before the files are published finds little
// left to do).
class BufferedFile {
 public:
  // Errors name `shown` (the file the user asked for), not the temporary path written. With
  // must_exist the file is never created: writing into a temporary another process made (and
  // may have removed, when the run failed) leaves no file behind.
  explicit BufferedFile(std::string path, std::string shown = "", bool must_exist = false);
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

  // Whether the buffers handed over so far went around the page cache (for tests).
  bool writes_directly() const;

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
  // Hands the buffer to the writing thread: all of it when `last`, else (writing directly) its
  // whole blocks, the rest starting the next buffer.
  void flush(bool last = false);
  [[noreturn]] void fail(int error);

  std::string shown_;
  AlignedBytes buffer_;
  std::size_t used_ = 0;
  std::unique_ptr<Writer> writer_;
};

// Waits for every file closed in the background; throws OutputError naming the first that
// failed (after all have ended).
void finish_background_writes();
// The same, ignoring failures (the files are being discarded).
void abandon_background_writes() noexcept;

}  // namespace partet
