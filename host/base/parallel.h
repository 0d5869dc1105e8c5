// parallel_for over [0, n) in contiguous chunks on up to `threads` threads; the
// calling thread takes the first chunk. Exceptions from any chunk are rethrown.
#pragma once
#include <algorithm>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace portalsim {

inline unsigned default_threads() { return std::max(1u, std::thread::hardware_concurrency()); }

inline void parallel_for(size_t n, unsigned threads, const std::function<void(size_t begin, size_t end)>& fn) {
  threads = static_cast<unsigned>(std::min<size_t>(std::max(1u, threads), n));
  if (threads <= 1) {
    if (n) fn(0, n);
    return;
  }
  std::exception_ptr error;
  std::mutex m;
  std::vector<std::thread> pool;
  auto run = [&](size_t t) {
    try {
      fn(n * t / threads, n * (t + 1) / threads);
    } catch (...) {
      std::lock_guard<std::mutex> lock(m);
      if (!error) error = std::current_exception();
    }
  };
  for (size_t t = 1; t < threads; ++t) pool.emplace_back(run, t);
  run(0);
  for (std::thread& th : pool) th.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace portalsim
