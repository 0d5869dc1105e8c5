// A file written by appending, with its length and XXH3-64 hash kept as it grows, so a
// run can checkpoint where it stands and a resumed run can truncate back to that point.
#pragma once
#include <cstdint>
#include <memory>
#include <span>
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

// Appends go to an aligned buffer and reach the file in large O_DIRECT writes, made by a
// background thread while the caller fills the other buffer: the page cache is skipped, so
// the writer runs at the disk's own speed. The last, partial block is written padded with
// zeros to a whole block (and written again as it fills); state() puts every byte appended
// so far into the file first, so a checkpoint's length and hash are what the file holds,
// and the file is cut back to its true length at finish(), on destruction (a run stopped
// cleanly) and on resume (a run killed). Where O_DIRECT is refused (some file systems
// return EINVAL), the same buffers go through the page cache instead.
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
  // Room for the next bytes, written in place (no copy): at least one byte, in the buffer
  // the file is written from; commit(n) then appends its first n (n <= room().size()).
  std::span<char> room();
  void commit(size_t n);
  uint64_t size() const { return bytes_; }  // bytes appended so far
  // The bytes appended so far, written into the file first (for a checkpoint).
  FileState state() const;
  // Closes and renames the partial file to its final name.
  void finish();
  // Whether writes bypass the page cache (O_DIRECT was accepted).
  bool direct() const { return direct_; }

  // Tests: make O_DIRECT look refused, at open (`at_open`) or at the first write (EINVAL).
  enum class RefuseDirect { no, at_open, at_write };
  static void refuse_direct_for_tests(RefuseDirect how);

 private:
  struct Writer;
  void submit_full();                                         // hands the full buffer to the writer thread
  void wait_writer() const;                                   // until the writer thread is idle; rethrows its error
  void write_at(const char* p, size_t n, uint64_t at) const;  // pwrite all; EINVAL: buffered from now
  void write_tail() const;                                    // the buffered bytes into the file (see state())
  void cut_back() noexcept;                                   // the file to its true length (after padded writes)

  std::string partial_, final_;
  std::string name_;
  uint64_t bytes_ = 0;
  void* hash_ = nullptr;  // XXH3_state_t
  int fd_ = -1;
  mutable bool direct_ = false;
  // The buffer being filled holds the file's bytes [buf_at_, buf_at_ + buf_len_); in direct
  // mode buf_at_ is block-aligned. `synced_`: bytes_ when state() last wrote the tail.
  char* bufs_[2] = {nullptr, nullptr};
  int active_ = 0;
  mutable size_t buf_len_ = 0;
  mutable uint64_t buf_at_ = 0, synced_ = 0;
  mutable uint64_t written_end_ = 0;             // the file's length as written (padding included)
  mutable uint64_t flushing_ = 0, flushed_ = 0;  // buffered mode: writeback started from / done up to
  std::unique_ptr<Writer> writer_;
};

}  // namespace portalsim
