#include "io/buffered_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <thread>

#include "partet/errors.hpp"

namespace partet {

// The file and the thread that writes the buffers handed to it, one at a time.
struct BufferedFile::Writer {
  // Writeback is started every this many bytes.
  static constexpr std::size_t kWritebackStep = std::size_t(64) << 20;

  int fd = -1;
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<char> pending;  // the buffer being written
  std::size_t pending_size = 0;
  bool busy = false, stopping = false;
  int error = 0;  // the first write's errno
  std::uint64_t written = 0, written_back = 0;
  std::thread thread;
  std::string shown;  // for the error of a file closed in the background

  // Writes everything or records why not; no more writes after a failure.
  void write_all(const char* p, std::size_t n) {
    while (n > 0 && error == 0) {
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
  void start(std::size_t buffer_size) {
    pending.resize(buffer_size);
    thread = std::thread([this] { run(); });
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

BufferedFile::BufferedFile(std::string path, std::string shown)
    : shown_(shown.empty() ? path : std::move(shown)), buffer_(kBufferSize), writer_(std::make_unique<Writer>()) {
  writer_->fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (writer_->fd < 0) fail(errno);
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

void BufferedFile::flush() {
  if (used_ == 0) return;
  Writer& w = *writer_;
  // Started at the first hand-over: a small file closed with close() is written without one.
  if (!w.thread.joinable()) w.start(buffer_.size());
  if (const int error = w.wait_idle(); error != 0) fail(error);
  {
    std::lock_guard<std::mutex> lock(w.mutex);
    buffer_.swap(w.pending);
    w.pending_size = used_;
    w.busy = true;
  }
  w.changed.notify_all();
  used_ = 0;
}

void BufferedFile::close() {
  Writer& w = *writer_;
  if (w.thread.joinable()) {
    flush();
  } else {
    w.write_all(data(), used_);  // a small file: never handed over, this thread writes it
    used_ = 0;
  }
  if (const int error = w.end(); error != 0) fail(error);
}

void BufferedFile::close_in_background() {
  flush();  // starts the thread if anything is left to write
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
