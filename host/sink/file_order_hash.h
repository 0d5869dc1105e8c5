// The XXH3-64 of a file in address order while it is written in another: the caller's
// extents (regions it fills, such as data.h5's chunks) are fed as their pieces are made,
// and the bytes between them (final before the run, such as HDF5's metadata) are read from
// the file when the hash reaches them. A piece that comes before the hash reaches it is
// held until it does. So a file written nearly in order is hashed from the cache, with no
// pass over it at the end.
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "sink/append_file.h"

namespace portalsim {

struct FileExtent {
  uint64_t address = 0;
  uint64_t size = 0;    // bytes allocated
  uint64_t filled = 0;  // the first `filled` bytes are fed; the rest are never written and read as zeros
};

class FileOrderHash {
 public:
  // `extents` sorted by address, disjoint, non-empty, inside [0, file_size); `fd` the open
  // file, read for the bytes between them. Nothing is hashed until start() or skip_to().
  FileOrderHash(int fd, std::string path, std::vector<FileExtent> extents, uint64_t file_size);
  FileOrderHash(const FileOrderHash&) = delete;
  FileOrderHash& operator=(const FileOrderHash&) = delete;
  ~FileOrderHash();

  // A new file: hashes the bytes before the first extent.
  void start();
  // A resumed one: hashes the file's bytes [0, to) as they are on disk; `to` is a position()
  // recorded earlier. Throws OutputError when it is not one.
  void skip_to(uint64_t to, unsigned threads);

  // Bytes [at, at + data.size()) of extent e, made. Each extent's bytes come in order; the
  // extents may come in any order (those ahead of the hash are held).
  void feed(size_t e, uint64_t at, std::string_view data);

  uint64_t position() const { return pos_; }  // bytes hashed: the file's [0, position())
  // Where that is: the extent the hash is in (extents.size() past the last) and how far into it.
  size_t extent() const { return cur_; }
  uint64_t into_extent() const { return at_; }
  uint64_t digest() const;  // XXH3-64 of those
  // The bytes fed and held (ahead of the hash), in file order: their count and XXH3-64.
  FileState held(const std::string& name) const;
  // Hashes what is left; every extent must be filled by now. The whole file's XXH3-64.
  uint64_t finish();

 private:
  void hash_file_bytes(uint64_t from, uint64_t to);  // read from the file
  void hash_zeros(uint64_t n);
  void advance();  // past every extent now complete, taking up held pieces on the way

  int fd_;
  std::string path_;
  std::vector<FileExtent> extents_;
  uint64_t file_size_;
  size_t cur_ = 0;   // the extent the hash is in (extents_.size(): past the last)
  uint64_t at_ = 0;  // and how far into it
  uint64_t pos_ = 0;
  std::map<size_t, std::string> held_;  // extent -> its first bytes, fed ahead of the hash
  struct StateFree {
    void operator()(void* s) const;
  };
  std::unique_ptr<void, StateFree> state_;
};

}  // namespace portalsim
