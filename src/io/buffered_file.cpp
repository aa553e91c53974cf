#include "io/buffered_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/vfs.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <new>
#include <system_error>
#include <thread>

#include "common/log.hpp"
#include "common/test_hooks.hpp"
#include "partet/errors.hpp"
#include "runner/interrupts.hpp"

namespace partet {

AlignedBytes::AlignedBytes(std::size_t size)
    : bytes_(size == 0 ? nullptr
                       : static_cast<char*>(
                             std::aligned_alloc(kAlignment, (size + kAlignment - 1) / kAlignment * kAlignment))),
      size_(size) {
  if (size > 0 && !bytes_) throw std::bad_alloc();
}

void AlignedBytes::Free::operator()(char* p) const noexcept { std::free(p); }

namespace {

constexpr std::size_t kBlock = AlignedBytes::kAlignment;

// Whether writes to `fd` should go around the page cache: a regular file on a local disk's
// filesystem (see the header), which accepts O_DIRECT. Network and parallel filesystems differ
// too much in how they treat direct writes to risk it.
bool start_direct_writes(int fd) {
#ifdef __linux__
  constexpr long kExt4 = 0xEF53, kXfs = 0x58465342, kBtrfs = 0x9123683E;
  struct stat file {};
  struct statfs filesystem {};
  if (::fstat(fd, &file) != 0 || !S_ISREG(file.st_mode) || ::fstatfs(fd, &filesystem) != 0) return false;
  const long type = static_cast<long>(filesystem.f_type);
  if (type != kExt4 && type != kXfs && type != kBtrfs) return false;
  const int flags = ::fcntl(fd, F_GETFL);
  return flags >= 0 && ::fcntl(fd, F_SETFL, flags | O_DIRECT) == 0;
#else
  (void)fd;
  return false;
#endif
}

}  // namespace

// The file and the thread that writes the buffers handed to it, one at a time.
struct BufferedFile::Writer {
  // Writeback is started every this many bytes.
  static constexpr std::size_t kWritebackStep = std::size_t(64) << 20;

  int fd = -1;
  std::mutex mutex;
  std::condition_variable changed;
  AlignedBytes pending;  // the buffer being written
  std::size_t pending_size = 0;
  bool busy = false, stopping = false;
  bool direct = false;  // writing around the page cache
  int error = 0;        // the first write's errno
  std::uint64_t written = 0, written_back = 0;
  std::thread thread;
  bool alone = false;  // no thread could be started: the caller writes
  std::string shown;  // for the error of a file closed in the background

  // Writes everything or records why not; no more writes after a failure. Writing directly,
  // whole blocks go directly and a shorter tail (the file's end) through the page cache.
  void write_all(const char* p, std::size_t n) {
    if (direct) {
      const std::size_t done = write_blocks_directly(p, written % kBlock == 0 ? n - n % kBlock : 0);
      p += done, n -= done;
      if (n > 0 && error == 0) stop_direct();
    }
    write_through_cache(p, n);
  }

  // Returns the bytes written; a filesystem that refuses after all (EINVAL) or a short write
  // ends the direct writes, and the caller writes the rest through the page cache.
  std::size_t write_blocks_directly(const char* p, std::size_t n) {
    std::size_t total = 0;
    while (total < n && error == 0 && direct) {
      if ((error = test_hooks::quota_refusal()) != 0) break;
      const ssize_t done = ::write(fd, p + total, n - total);
      if (done < 0) {
        if (errno == EINVAL)
          stop_direct();
        else if (errno != EINTR)
          error = errno;
        continue;
      }
      total += static_cast<std::size_t>(done), written += static_cast<std::uint64_t>(done);
      if (written % kBlock != 0) stop_direct();
    }
    return total;
  }

  void stop_direct() {
    const int flags = ::fcntl(fd, F_GETFL);
    if (flags < 0 || ::fcntl(fd, F_SETFL, flags & ~O_DIRECT) != 0) error = errno;
    direct = false;
  }

  void write_through_cache(const char* p, std::size_t n) {
    while (n > 0 && error == 0) {
      if ((error = test_hooks::quota_refusal()) != 0) break;
      const ssize_t done = ::write(fd, p, n);
      if (done < 0) {
        if (errno != EINTR) error = errno;
        continue;
      }
      p += done, n -= static_cast<std::size_t>(done), written += static_cast<std::uint64_t>(done);
    }
#ifdef __linux__
    if (error == 0 && written - written_back >= kWritebackStep) {
      // Only starts the disk writes; errors surface at fsync.
      (void)::sync_file_range(fd, static_cast<off_t>(written_back), static_cast<off_t>(written - written_back),
                              SYNC_FILE_RANGE_WRITE);
      written_back = written;
    }
#endif
  }

  void run() {
    std::unique_lock<std::mutex> lock(mutex);
    for (;;) {
      changed.wait(lock, [&] { return busy || stopping; });
      if (!busy) return;
      lock.unlock();
      write_all(pending.data(), pending_size);
      lock.lock();
      busy = false;
      changed.notify_all();
    }
  }

  // Waits until the thread has written what it was given; returns the first error (0: none).
  int wait_idle() {
    std::unique_lock<std::mutex> lock(mutex);
    changed.wait(lock, [&] { return !busy; });
    return error;
  }

  void stop() {
    if (!thread.joinable()) return;
    {
      std::lock_guard<std::mutex> lock(mutex);
      stopping = true;
    }
    changed.notify_all();
    thread.join();
  }

  // Starts the thread, with a buffer of its own to write from (small files never need one).
  // Without room for its stack (a tight ulimit -v) the caller writes each buffer itself.
  void start(std::size_t buffer_size) {
    pending = AlignedBytes(buffer_size);
    direct = start_direct_writes(fd);
    try {
      thread = std::thread([this] { run(); });
    } catch (const std::system_error&) {
      alone = true;
    }
  }

  // Waits for what the thread was given, stops it and closes the file; returns the first error
  // (0: none).
  int end() {
    wait_idle();
    stop();
    int first_error = error;
    if (fd >= 0 && ::close(fd) != 0 && first_error == 0) first_error = errno;
    fd = -1;
    return first_error;
  }
};

namespace {

// The files closed in the background, until finish_background_writes (one job at a time per
// process, so one list; the mutex only guards it against misuse from several threads).
std::mutex background_mutex;
std::vector<std::unique_ptr<BufferedFile::Writer>>& background_writers() {
  static auto* writers = new std::vector<std::unique_ptr<BufferedFile::Writer>>;
  return *writers;
}

}  // namespace

BufferedFile::BufferedFile(std::string path, std::string shown, bool must_exist)
    : shown_(shown.empty() ? path : std::move(shown)), buffer_(kBufferSize), writer_(std::make_unique<Writer>()) {
  int error = 0;
  {
    // An interrupt removes the temporaries and ends the run: an open that may create the file
    // must not fall between the two (it would make a removed temporary again). It waits for the
    // interrupt's cleanup (forever: the process ends), or the cleanup waits for it.
    const interrupts::Deferred held("");
    writer_->fd = ::open(path.c_str(), O_WRONLY | (must_exist ? 0 : O_CREAT) | O_TRUNC | O_CLOEXEC, 0666);
    error = errno;
  }
  if (writer_->fd < 0) fail(error);
}

BufferedFile::~BufferedFile() {
  if (writer_) writer_->end();  // unless closed in the background
}

void BufferedFile::bytes(const void* p, std::size_t n) {
  const char* from = static_cast<const char*>(p);
  while (n > 0) {
    if (used_ == buffer_.size()) flush();
    const std::size_t take = std::min(n, buffer_.size() - used_);
    std::memcpy(data() + used_, from, take);
    used_ += take, from += take, n -= take;
  }
}

void BufferedFile::flush(bool last) {
  if (used_ == 0) return;
  Writer& w = *writer_;
  // Started at the first hand-over: a small file closed with close() is written without one.
  if (!w.thread.joinable() && !w.alone) {
    w.start(buffer_.size());
    if (w.direct) log::debug("writing '" + shown_ + "' around the page cache (O_DIRECT)");
  }
  if (const int error = w.wait_idle(); error != 0) fail(error);
  const std::size_t handed = w.direct && !last ? used_ - used_ % kBlock : used_;
  if (handed == 0) return;
  if (w.alone) {
    w.write_all(data(), handed);
    std::memmove(data(), data() + handed, used_ - handed);
    used_ -= handed;
    if (w.error != 0) fail(w.error);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(w.mutex);
    buffer_.swap(w.pending);
    std::memcpy(buffer_.data(), w.pending.data() + handed, used_ - handed);
    w.pending_size = handed;
    w.busy = true;
  }
  w.changed.notify_all();
  used_ -= handed;
  if (!last) test_hooks::buffer_handed();
}

bool BufferedFile::writes_directly() const { return writer_ && writer_->direct; }

void BufferedFile::close() {
  Writer& w = *writer_;
  if (w.thread.joinable() || w.alone) {
    flush(true);
  } else {
    w.write_all(data(), used_);  // a small file: never handed over, this thread writes it
    used_ = 0;
  }
  if (const int error = w.end(); error != 0) fail(error);
}

void BufferedFile::close_in_background() {
  flush(true);  // starts the thread if anything is left to write
  writer_->shown = shown_;
  std::lock_guard<std::mutex> lock(background_mutex);
  background_writers().push_back(std::move(writer_));
}

void finish_background_writes() {
  std::vector<std::unique_ptr<BufferedFile::Writer>> writers;
  {
    std::lock_guard<std::mutex> lock(background_mutex);
    writers.swap(background_writers());
  }
  std::string failure;
  for (const auto& w : writers)
    if (const int error = w->end(); error != 0 && failure.empty())
      failure = "cannot write '" + w->shown + "': " + std::strerror(error);
  if (!failure.empty()) throw OutputError(failure);
}

void abandon_background_writes() noexcept {
  try {
    finish_background_writes();
  } catch (...) {
  }
}

void BufferedFile::fail(int error) { throw OutputError("cannot write '" + shown_ + "': " + std::strerror(error)); }

}  // namespace partet
