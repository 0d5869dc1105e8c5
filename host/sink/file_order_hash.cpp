#include "sink/file_order_hash.h"

#include <xxhash.h>

#include <algorithm>
#include <stdexcept>

#include "base/error.h"
#include "sink/h5_file.h"

namespace portalsim {

namespace {
XXH3_state_t* as_state(void* p) { return static_cast<XXH3_state_t*>(p); }
}  // namespace

void FileOrderHash::StateFree::operator()(void* s) const { XXH3_freeState(as_state(s)); }

FileOrderHash::FileOrderHash(int fd, std::string path, std::vector<FileExtent> extents, uint64_t file_size)
    : fd_(fd), path_(std::move(path)), extents_(std::move(extents)), file_size_(file_size) {
  uint64_t end = 0;
  for (const FileExtent& x : extents_) {
    if (x.size == 0 || x.filled > x.size || x.address < end || x.address + x.size > file_size_)
      throw std::logic_error("FileOrderHash: extents must be sorted, disjoint, non-empty and inside the file");
    end = x.address + x.size;
  }
  state_.reset(XXH3_createState());
  if (!state_) throw std::bad_alloc();
  XXH3_64bits_reset(as_state(state_.get()));
}

FileOrderHash::~FileOrderHash() = default;

void FileOrderHash::hash_file_bytes(uint64_t from, uint64_t to) {
  char buf[64 << 10];
  for (; from < to;) {
    const size_t n = static_cast<size_t>(std::min<uint64_t>(to - from, sizeof buf));
    read_at(fd_, buf, n, from, path_, "to hash it");
    XXH3_64bits_update(as_state(state_.get()), buf, n);
    from += n;
  }
}

void FileOrderHash::hash_zeros(uint64_t n) {
  static const char zeros[64 << 10] = {};
  for (; n > 0;) {
    const size_t k = static_cast<size_t>(std::min<uint64_t>(n, sizeof zeros));
    XXH3_64bits_update(as_state(state_.get()), zeros, k);
    n -= k;
  }
}

void FileOrderHash::start() {
  const uint64_t to = extents_.empty() ? file_size_ : extents_[0].address;
  hash_file_bytes(0, to);
  pos_ = to;
  cur_ = 0;
  at_ = 0;
  advance();
}

void FileOrderHash::skip_to(uint64_t to, unsigned threads) {
  // The extent `to` lies in (in its filled part), or the end of the file.
  auto it = std::upper_bound(extents_.begin(), extents_.end(), to,
                             [](uint64_t a, const FileExtent& x) { return a < x.address; });
  const bool at_end = to == file_size_ && (extents_.empty() || it == extents_.end());
  if (!at_end && (it == extents_.begin() || to >= std::prev(it)->address + std::prev(it)->filled))
    throw OutputError(path_ + ": the checkpoint's position " + std::to_string(to) +
                      " is not one this file's writing passes through; the run cannot be resumed");
  if (to > 0) hash_range(fd_, 0, to, state_.get(), path_, threads);
  pos_ = to;
  if (at_end) {
    cur_ = extents_.size();
    at_ = 0;
  } else {
    cur_ = static_cast<size_t>(std::prev(it) - extents_.begin());
    at_ = to - extents_[cur_].address;
  }
  held_.clear();
}

void FileOrderHash::feed(size_t e, uint64_t at, std::string_view data) {
  if (e >= extents_.size() || at + data.size() > extents_[e].filled)
    throw std::logic_error("FileOrderHash: a piece outside its extent's filled bytes");
  if (e == cur_ && at == at_) {
    XXH3_64bits_update(as_state(state_.get()), data.data(), data.size());
    at_ += data.size();
    pos_ += data.size();
    advance();
    return;
  }
  std::string& h = held_[e];
  if (e <= cur_ || h.size() != at) throw std::logic_error("FileOrderHash: pieces out of order");
  h.append(data);
}

void FileOrderHash::advance() {
  while (cur_ < extents_.size()) {
    const FileExtent& x = extents_[cur_];
    if (at_ == 0)
      if (auto h = held_.find(cur_); h != held_.end()) {
        XXH3_64bits_update(as_state(state_.get()), h->second.data(), h->second.size());
        at_ = h->second.size();
        pos_ += at_;
        held_.erase(h);
      }
    if (at_ < x.filled) return;
    hash_zeros(x.size - x.filled);
    const uint64_t next = cur_ + 1 < extents_.size() ? extents_[cur_ + 1].address : file_size_;
    hash_file_bytes(x.address + x.size, next);
    pos_ = next;
    ++cur_;
    at_ = 0;
  }
}

uint64_t FileOrderHash::digest() const { return XXH3_64bits_digest(as_state(state_.get())); }

FileState FileOrderHash::held(const std::string& name) const {
  XXH3_state_t* h = XXH3_createState();
  if (!h) throw std::bad_alloc();
  XXH3_64bits_reset(h);
  FileState s{name, 0, 0};
  for (const auto& [e, bytes] : held_) {
    XXH3_64bits_update(h, bytes.data(), bytes.size());
    s.bytes += bytes.size();
  }
  s.xxh3 = XXH3_64bits_digest(h);
  XXH3_freeState(h);
  return s;
}

uint64_t FileOrderHash::finish() {
  if (cur_ < extents_.size() || !held_.empty())
    throw std::logic_error("FileOrderHash: finished before every extent was filled");
  return digest();
}

}  // namespace portalsim
