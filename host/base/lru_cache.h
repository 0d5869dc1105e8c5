// A map that keeps at most `capacity` entries and drops the least recently used: the
// backends' tables derived from the knobs, which a long-lived `serve` trying knob after
// knob would otherwise grow without end.
#pragma once
#include <algorithm>
#include <cstddef>
#include <list>
#include <map>
#include <utility>

namespace portalsim {

template <class Key, class Value>
class LruCache {
 public:
  explicit LruCache(size_t capacity) : capacity_(std::max<size_t>(capacity, 1)) {}

  // The entry for `key`, made with Value{} when absent (then, past the capacity, the least
  // recently used other entry is dropped). A reference stays valid until its entry is
  // dropped; the entry returned last is never the next one dropped.
  Value& operator[](const Key& key) {
    if (auto it = entries_.find(key); it != entries_.end()) {
      order_.splice(order_.begin(), order_, it->second.second);
      return it->second.first;
    }
    if (entries_.size() >= capacity_) {
      entries_.erase(order_.back());
      order_.pop_back();
    }
    order_.push_front(key);
    auto [it, inserted] = entries_.try_emplace(key);
    it->second.second = order_.begin();
    return it->second.first;
  }
  size_t size() const { return entries_.size(); }
  size_t capacity() const { return capacity_; }
  // Keeps at least `capacity` entries from now on (never fewer than before).
  void reserve(size_t capacity) { capacity_ = std::max(capacity_, capacity); }
  bool contains(const Key& key) const { return entries_.count(key) != 0; }

 private:
  size_t capacity_;
  std::list<Key> order_;  // most recently used first
  std::map<Key, std::pair<Value, typename std::list<Key>::iterator>> entries_;
};

}  // namespace portalsim
