// Finished objects whose buffers the next user takes again, so that a long run touches no
// new pages: the generate pipeline's jobs and the Python stream's batches.
#pragma once
#include <cstddef>
#include <limits>
#include <memory>
#include <mutex>
#include <vector>

namespace portalsim {

template <class T>
class Recycler {
 public:
  // Keeps at most `keep` objects; those given past it are freed.
  explicit Recycler(size_t keep = std::numeric_limits<size_t>::max()) : keep_(keep) {}

  // A kept object, or a new one when none is kept.
  std::unique_ptr<T> take() {
    std::lock_guard<std::mutex> lock(m_);
    if (free_.empty()) return std::make_unique<T>();
    std::unique_ptr<T> t = std::move(free_.back());
    free_.pop_back();
    return t;
  }
  void give(std::unique_ptr<T> t) {
    std::lock_guard<std::mutex> lock(m_);
    if (free_.size() < keep_) free_.push_back(std::move(t));
  }

 private:
  const size_t keep_;
  std::mutex m_;
  std::vector<std::unique_ptr<T>> free_;
};

}  // namespace portalsim
