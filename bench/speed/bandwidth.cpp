#include "speed/bandwidth.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <thread>
#include <vector>

#include "base/error.h"

namespace portalsim::speed {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void fill_parallel(char* p, size_t bytes, unsigned threads, int value) {
  std::vector<std::thread> pool;
  const size_t slice = (bytes + threads - 1) / threads;
  for (unsigned t = 0; t < threads; ++t) {
    const size_t a = std::min(bytes, t * slice), b = std::min(bytes, a + slice);
    pool.emplace_back([=] { std::memset(p + a, value, b - a); });
  }
  for (std::thread& t : pool) t.join();
}
}  // namespace

double memory_write_rate(size_t bytes, unsigned threads) {
  std::unique_ptr<char[]> buf(new char[bytes]);
  threads = std::max(1u, threads);
  fill_parallel(buf.get(), bytes, threads, 1);  // page faults happen here, not in the timing
  const auto t0 = Clock::now();
  fill_parallel(buf.get(), bytes, threads, 2);
  const double s = since(t0);
  volatile char sink = buf[bytes / 2];
  (void)sink;
  return static_cast<double>(bytes) / s;
}

DiskRate disk_write_rate(const std::string& dir, size_t bytes) {
  constexpr size_t kBlock = 16 << 20;
  const std::string path =
      (std::filesystem::path(dir) / ("portalsim-bench-disk-" + std::to_string(::getpid()))).string();
  DiskRate r;
  int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_DIRECT, 0600);
  r.direct = fd >= 0;
  if (fd < 0 && errno == EINVAL) fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  if (fd < 0) throw OutputError("--dir: cannot write " + path + ": " + std::strerror(errno));
  void* mem = nullptr;
  if (::posix_memalign(&mem, 4096, kBlock) != 0) {
    ::close(fd);
    ::unlink(path.c_str());
    throw std::bad_alloc();
  }
  std::unique_ptr<char, decltype(&std::free)> block(static_cast<char*>(mem), &std::free);
  // Fresh, non-zero bytes: a filesystem may store zeros sparsely.
  for (size_t i = 0; i < kBlock; ++i) block.get()[i] = static_cast<char>(i * 2654435761u >> 24);
  const auto t0 = Clock::now();
  std::string failed;
  for (size_t done = 0; done < bytes && failed.empty(); done += kBlock) {
    const size_t n = std::min(kBlock, bytes - done);
    // O_DIRECT needs whole blocks: round the last one up.
    const size_t whole = (n + 4095) / 4096 * 4096;
    const ssize_t w = ::write(fd, block.get(), whole);
    if (w < 0)
      failed = std::strerror(errno);
    else if (static_cast<size_t>(w) != whole)
      failed = "short write (disk full?)";
  }
  if (failed.empty() && !r.direct && ::fsync(fd) != 0) failed = std::strerror(errno);
  const double s = since(t0);
  ::close(fd);
  ::unlink(path.c_str());
  if (!failed.empty()) throw OutputError("--dir: writing " + path + " failed: " + failed);
  r.bytes_per_s = static_cast<double>(bytes) / s;
  return r;
}

}  // namespace portalsim::speed
