#include "sink/append_file.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xxhash.h>

#include <atomic>
#include <cerrno>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <exception>
#include <filesystem>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "base/error.h"

namespace portalsim {

namespace {
XXH3_state_t* state_of(void* p) { return static_cast<XXH3_state_t*>(p); }
}  // namespace

std::string xxh3_hex(uint64_t hash) {
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
  return hex;
}

namespace {

// Bytes [at, end) of `fd` mapped and populated (MAP_POPULATE), `base` the page it starts
// in; null where the file cannot be mapped.
struct Window {
  uint64_t base = 0, at = 0, end = 0;
  void* map = nullptr;
};

Window map_window(int fd, uint64_t at, uint64_t end) {
  static const uint64_t page = static_cast<uint64_t>(::sysconf(_SC_PAGESIZE));
  Window w{at / page * page, at, end, nullptr};
  void* m = ::mmap(nullptr, static_cast<size_t>(end - w.base), PROT_READ, MAP_SHARED | MAP_POPULATE, fd,
                   static_cast<off_t>(w.base));
  if (m != MAP_FAILED) w.map = m;
  return w;
}

// Feeds window `w` to `h` and unmaps it; read() where it could not be mapped.
void hash_window(int fd, const Window& w, XXH3_state_t* h, std::vector<char>& buf, const std::string& path,
                 const char* what) {
  if (w.map) {
    XXH3_64bits_update(h, static_cast<const char*>(w.map) + (w.at - w.base), static_cast<size_t>(w.end - w.at));
    ::munmap(w.map, static_cast<size_t>(w.end - w.base));
    return;
  }
  buf.resize(1u << 20);
  for (uint64_t at = w.at; at < w.end;) {
    const ssize_t r = ::pread(fd, buf.data(), static_cast<size_t>(std::min<uint64_t>(w.end - at, buf.size())),
                              static_cast<off_t>(at));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) throw OutputError(path + ": cannot read back " + what + ": " + std::strerror(r < 0 ? errno : EIO));
    XXH3_64bits_update(h, buf.data(), static_cast<size_t>(r));
    at += static_cast<uint64_t>(r);
  }
}

// Feeds bytes [offset, offset + n) of `fd` to `h`, mapped a window at a time: the hash reads
// the page cache in place, without read()'s copy (read() where the file cannot be mapped).
// Mapping a window (the kernel filling its page table) costs about twice what hashing it
// does, so with `threads` >= 2 a second thread maps the windows ahead while this one hashes
// and unmaps them. Throws OutputError naming `path` (`what` says why it was read).
void hash_mapped(int fd, uint64_t offset, uint64_t n, XXH3_state_t* h, const std::string& path, const char* what,
                 unsigned threads) {
  struct stat st {};
  if (::fstat(fd, &st) != 0 || static_cast<uint64_t>(st.st_size) < offset + n)
    throw OutputError(path + ": cannot read back " + what + ": shorter than " + std::to_string(offset + n) + " bytes");
  constexpr uint64_t kWindow = 8ull << 20;  // a multiple of the page size
  constexpr size_t kAhead = 4;              // windows mapped and not yet hashed, at most
  std::vector<char> buf;
  const uint64_t end = offset + n;
  const auto window_end = [&](uint64_t at) { return std::min(end, (at / kWindow + 1) * kWindow); };
  if (threads < 2 || n <= 2 * kWindow) {
    for (uint64_t at = offset; at < end; at = window_end(at))
      hash_window(fd, map_window(fd, at, window_end(at)), h, buf, path, what);
    return;
  }
  std::mutex m;
  std::condition_variable cv;
  std::deque<Window> ready;
  bool stop = false;
  std::thread mapper([&] {
    for (uint64_t at = offset; at < end; at = window_end(at)) {
      {
        std::unique_lock<std::mutex> lock(m);
        cv.wait(lock, [&] { return ready.size() < kAhead || stop; });
        if (stop) return;
      }
      const Window w = map_window(fd, at, window_end(at));
      {
        std::lock_guard<std::mutex> lock(m);
        ready.push_back(w);
      }
      cv.notify_all();
    }
  });
  std::exception_ptr error;
  try {
    for (uint64_t at = offset; at < end; at = window_end(at)) {
      Window w;
      {
        std::unique_lock<std::mutex> lock(m);
        cv.wait(lock, [&] { return !ready.empty(); });
        w = ready.front();
        ready.pop_front();
      }
      cv.notify_all();
      hash_window(fd, w, h, buf, path, what);
    }
  } catch (...) {
    error = std::current_exception();
  }
  {
    std::lock_guard<std::mutex> lock(m);
    stop = true;
  }
  cv.notify_all();
  mapper.join();
  for (const Window& w : ready)
    if (w.map) ::munmap(w.map, static_cast<size_t>(w.end - w.base));
  if (error) std::rethrow_exception(error);
}

}  // namespace

void hash_range(int fd, uint64_t offset, uint64_t n, void* xxh3_state, const std::string& path, unsigned threads) {
  hash_mapped(fd, offset, n, state_of(xxh3_state), path, "for resume", threads);
}

FileState hash_file(const std::string& dir, const std::string& name, unsigned threads) {
  const std::string path = (std::filesystem::path(dir) / name).string();
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw OutputError(path + ": cannot open: " + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const int err = errno;
    ::close(fd);
    throw OutputError(path + ": cannot read: " + std::strerror(err));
  }
  XXH3_state_t* h = XXH3_createState();
  if (!h) {
    ::close(fd);
    throw std::bad_alloc();
  }
  XXH3_64bits_reset(h);
  FileState s{name, static_cast<uint64_t>(st.st_size), 0};
  try {
    hash_mapped(fd, 0, s.bytes, h, path, "to hash it", threads);
  } catch (...) {
    ::close(fd);
    XXH3_freeState(h);
    throw;
  }
  ::close(fd);
  s.xxh3 = XXH3_64bits_digest(h);
  XXH3_freeState(h);
  return s;
}

namespace {

// O_DIRECT's alignment (of memory, file offset and length): a multiple of every logical
// block size in use, and of the page size.
constexpr uint64_t kBlock = 4096;
// Each of the two buffers: large enough that a write costs the disk little more than its
// bytes (dd's 1 MiB already nears the disk's speed), small enough for a dozen open files.
constexpr size_t kBuffer = 4u << 20;

std::atomic<AppendFile::RefuseDirect> g_refuse{AppendFile::RefuseDirect::no};

char* aligned_buffer() {
  void* p = std::aligned_alloc(kBlock, kBuffer);
  if (!p) throw std::bad_alloc();
  return static_cast<char*>(p);
}

}  // namespace

void AppendFile::refuse_direct_for_tests(RefuseDirect how) { g_refuse = how; }

// The thread that writes full buffers while the caller fills the other one.
struct AppendFile::Writer {
  std::mutex m;
  std::condition_variable cv;
  bool busy = false, stop = false;
  const char* data = nullptr;
  size_t n = 0;
  uint64_t at = 0;
  std::exception_ptr error;
  std::thread thread;
};

AppendFile::AppendFile(const std::string& dir, const std::string& name, const FileState* resume)
    : partial_((std::filesystem::path(dir) / (name + ".partial")).string()),
      final_((std::filesystem::path(dir) / name).string()),
      name_(name) {
  hash_ = XXH3_createState();
  if (!hash_) throw std::bad_alloc();
  XXH3_64bits_reset(state_of(hash_));
  bufs_[0] = aligned_buffer();
  if (resume) {
    // A run that died while renaming its finished files: take the file back.
    std::error_code ec;
    if (!std::filesystem::exists(partial_, ec) && std::filesystem::exists(final_, ec))
      std::filesystem::rename(final_, partial_, ec);
    fd_ = ::open(partial_.c_str(), O_RDWR | O_CLOEXEC);
    if (fd_ < 0) throw OutputError(partial_ + ": cannot resume: " + std::strerror(errno));
    const off_t size = ::lseek(fd_, 0, SEEK_END);
    if (size < 0 || static_cast<uint64_t>(size) < resume->bytes)
      throw OutputError(partial_ + ": shorter than the checkpoint says (" + std::to_string(size) + " < " +
                        std::to_string(resume->bytes) + " bytes); the run cannot be resumed, start it again");
    // Past the checkpoint: rows written after it, and a padded last block.
    if (::ftruncate(fd_, static_cast<off_t>(resume->bytes)) != 0)
      throw OutputError(partial_ + ": cannot truncate for resume: " + std::strerror(errno));
    // Hash the kept prefix again: it must be what the checkpoint recorded. Appends go on
    // from its end.
    hash_range(fd_, 0, resume->bytes, hash_, partial_);
    if (XXH3_64bits_digest(state_of(hash_)) != resume->xxh3)
      throw OutputError(partial_ + ": its contents differ from the checkpoint; the run cannot be resumed");
    bytes_ = synced_ = written_end_ = flushing_ = flushed_ = resume->bytes;
    // The partial last block goes back into the buffer, to be written whole again.
    buf_at_ = bytes_ / kBlock * kBlock;
    buf_len_ = static_cast<size_t>(bytes_ - buf_at_);
    for (size_t got = 0; got < buf_len_;) {
      const ssize_t r = ::pread(fd_, bufs_[0] + got, buf_len_ - got, static_cast<off_t>(buf_at_ + got));
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) throw OutputError(partial_ + ": cannot read back for resume: " + std::strerror(r < 0 ? errno : EIO));
      got += static_cast<size_t>(r);
    }
  } else {
    fd_ = ::open(partial_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd_ < 0) throw OutputError(partial_ + ": cannot create: " + std::strerror(errno));
  }
  // Direct writes where the file system takes them; else (EINVAL) the page cache.
  const int flags = ::fcntl(fd_, F_GETFL);
  direct_ = g_refuse != RefuseDirect::at_open && flags >= 0 && ::fcntl(fd_, F_SETFL, flags | O_DIRECT) == 0;
  if (!direct_) {
    buf_at_ = bytes_;
    buf_len_ = 0;
  }
}

AppendFile::~AppendFile() {
  if (fd_ >= 0) {
    // A run stopped (cleanly or by an error): the file holds what was appended, no padding.
    try {
      wait_writer();
      write_tail();
    } catch (...) {
    }
    cut_back();
  }
  if (writer_) {
    {
      std::lock_guard<std::mutex> lock(writer_->m);
      writer_->stop = true;
    }
    writer_->cv.notify_all();
    writer_->thread.join();
  }
  if (fd_ >= 0) ::close(fd_);
  std::free(bufs_[0]);
  std::free(bufs_[1]);
  XXH3_freeState(state_of(hash_));
}

void AppendFile::write_at(const char* p, size_t n, uint64_t at) const {
  bool refuse = direct_ && g_refuse == RefuseDirect::at_write;
  for (size_t done = 0; done < n;) {
    const ssize_t w = refuse ? (errno = EINVAL, -1) : ::pwrite(fd_, p + done, n - done, static_cast<off_t>(at + done));
    if (w < 0 && errno == EINTR) continue;
    if (w < 0 && errno == EINVAL && direct_) {
      // The file system took O_DIRECT at open but not this write: the page cache from now on.
      refuse = false;
      const int flags = ::fcntl(fd_, F_GETFL);
      if (flags < 0 || ::fcntl(fd_, F_SETFL, flags & ~O_DIRECT) != 0)
        throw OutputError(partial_ + ": write failed: " + std::strerror(EINVAL));
      direct_ = false;
      continue;
    }
    if (w < 0) throw OutputError(partial_ + ": write failed: " + std::strerror(errno));
    done += static_cast<size_t>(w);
  }
  written_end_ = std::max(written_end_, at + n);
  if (direct_) return;
  // Through the page cache, large outputs still stream to the disk as they are written,
  // rather than piling up until the kernel throttles the writer: every kWindow bytes, start
  // the writeback of the window just written, wait for the one before it and drop it from
  // the cache. Hints only; finish() fsyncs, and a resumed run reads back what is there.
  constexpr uint64_t kWindow = 32ull << 20;
  const uint64_t end = at + n;
  if (end >= flushing_ + kWindow) {
    ::sync_file_range(fd_, static_cast<off_t>(flushing_), static_cast<off_t>(end - flushing_), SYNC_FILE_RANGE_WRITE);
    if (flushing_ > flushed_) {
      ::sync_file_range(fd_, static_cast<off_t>(flushed_), static_cast<off_t>(flushing_ - flushed_),
                        SYNC_FILE_RANGE_WAIT_BEFORE | SYNC_FILE_RANGE_WRITE | SYNC_FILE_RANGE_WAIT_AFTER);
      ::posix_fadvise(fd_, static_cast<off_t>(flushed_), static_cast<off_t>(flushing_ - flushed_), POSIX_FADV_DONTNEED);
      flushed_ = flushing_;
    }
    flushing_ = end;
  }
}

void AppendFile::wait_writer() const {
  if (!writer_) return;
  std::unique_lock<std::mutex> lock(writer_->m);
  writer_->cv.wait(lock, [&] { return !writer_->busy; });
  if (writer_->error) std::rethrow_exception(std::exchange(writer_->error, nullptr));
}

void AppendFile::submit_full() {
  if (!writer_) {
    bufs_[1] = aligned_buffer();
    writer_ = std::make_unique<Writer>();
    writer_->thread = std::thread([this, w = writer_.get()] {
      std::unique_lock<std::mutex> lock(w->m);
      for (;;) {
        w->cv.wait(lock, [&] { return w->busy || w->stop; });
        if (w->stop) return;
        lock.unlock();
        std::exception_ptr error;
        try {
          write_at(w->data, w->n, w->at);
        } catch (...) {
          error = std::current_exception();
        }
        lock.lock();
        w->error = error;
        w->busy = false;
        w->cv.notify_all();
      }
    });
  }
  wait_writer();  // the other buffer is free again
  {
    std::lock_guard<std::mutex> lock(writer_->m);
    writer_->data = bufs_[active_];
    writer_->n = buf_len_;
    writer_->at = buf_at_;
    writer_->busy = true;
  }
  writer_->cv.notify_all();
  buf_at_ += buf_len_;
  buf_len_ = 0;
  active_ ^= 1;
}

std::span<char> AppendFile::room() { return {bufs_[active_] + buf_len_, kBuffer - buf_len_}; }

void AppendFile::commit(size_t n) {
  XXH3_64bits_update(state_of(hash_), bufs_[active_] + buf_len_, n);
  bytes_ += n;
  buf_len_ += n;
  if (buf_len_ == kBuffer) submit_full();
}

void AppendFile::append(std::string_view data) {
  while (!data.empty()) {
    const std::span<char> r = room();
    const size_t n = std::min(data.size(), r.size());
    std::memcpy(r.data(), data.data(), n);
    commit(n);
    data.remove_prefix(n);
  }
}

void AppendFile::write_tail() const {
  if (synced_ == bytes_ || buf_len_ == 0) {
    synced_ = bytes_;
    return;
  }
  char* buf = bufs_[active_];
  if (direct_) {
    // Whole blocks only: the last one padded with zeros, to be written again as it fills.
    const size_t padded = (buf_len_ + kBlock - 1) / kBlock * kBlock;
    std::memset(buf + buf_len_, 0, padded - buf_len_);
    write_at(buf, padded, buf_at_);
  } else {
    write_at(buf, buf_len_, buf_at_);
  }
  if (direct_) {  // (write_at may have fallen back to the page cache)
    const size_t whole = buf_len_ / kBlock * kBlock;
    std::memmove(buf, buf + whole, buf_len_ - whole);
    buf_at_ += whole;
    buf_len_ -= whole;
  } else {
    buf_at_ += buf_len_;
    buf_len_ = 0;
  }
  synced_ = bytes_;
}

void AppendFile::cut_back() noexcept {
  if (written_end_ > bytes_ && ::ftruncate(fd_, static_cast<off_t>(bytes_)) == 0) written_end_ = bytes_;
}

FileState AppendFile::state() const {
  wait_writer();
  write_tail();
  return FileState{name_, bytes_, XXH3_64bits_digest(state_of(hash_))};
}

void AppendFile::finish() {
  if (fd_ >= 0) {
    wait_writer();
    write_tail();
    if (written_end_ > bytes_ && ::ftruncate(fd_, static_cast<off_t>(bytes_)) != 0)
      throw OutputError(partial_ + ": cannot cut to length: " + std::strerror(errno));
    written_end_ = bytes_;
    if (::fsync(fd_) != 0) throw OutputError(partial_ + ": fsync failed: " + std::strerror(errno));
    ::close(fd_);
    fd_ = -1;
  }
  std::error_code ec;
  std::filesystem::rename(partial_, final_, ec);
  if (ec) throw OutputError(final_ + ": cannot move into place: " + ec.message());
}

}  // namespace portalsim
