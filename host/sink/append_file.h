// A file written by appending, with its length and XXH3-64 hash kept as it grows, so a
// run can checkpoint where it stands and a resumed run can truncate back to that point.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>

namespace portalsim {

struct FileState {
  std::string name;  // relative to the output folder, final name
  uint64_t bytes = 0;
  uint64_t xxh3 = 0;  // XXH3-64 of the bytes so far
};

// 16 lower-case hexadecimal digits, as manifests record an XXH3-64.
std::string xxh3_hex(uint64_t hash);

// Feeds bytes [offset, offset + n) of the open file `fd` to an XXH3-64 state
// (XXH3_state_t*): a resumed run re-hashing what it keeps. With `threads` >= 2, a second
// thread maps the file ahead of the hash. Throws OutputError naming `path`.
void hash_range(int fd, uint64_t offset, uint64_t n, void* xxh3_state, const std::string& path, unsigned threads = 1);

// The state of a finished file dir/name (its size and XXH3-64), read as hash_range reads.
// Throws OutputError.
FileState hash_file(const std::string& dir, const std::string& name, unsigned threads = 1);

class AppendFile {
 public:
  // Opens dir/(name + ".partial"). With `resume`, truncates it to resume->bytes (it must
  // be at least that long) and hashes that prefix again; otherwise creates it empty.
  AppendFile(const std::string& dir, const std::string& name, const FileState* resume = nullptr);
  AppendFile(const AppendFile&) = delete;
  AppendFile& operator=(const AppendFile&) = delete;
  ~AppendFile();

  void append(std::string_view data);
  void append(const void* data, size_t n) { append(std::string_view(static_cast<const char*>(data), n)); }
  FileState state() const;
  // Closes and renames the partial file to its final name.
  void finish();

 private:
  std::string partial_, final_;
  std::string name_;
  uint64_t bytes_ = 0;
  uint64_t flushing_ = 0, flushed_ = 0;  // writeback started from / done up to (see append)
  void* hash_ = nullptr;                 // XXH3_state_t
  int fd_ = -1;
};

}  // namespace portalsim
