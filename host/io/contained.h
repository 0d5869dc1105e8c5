// Reading a foreign file in a child process: a library that crashes or overflows on a
// crafted file (libhdf5 1.10.8 reads past a heap buffer on a corrupt global heap, see
// tests/fuzz/README.md) then takes down only the child, and the parent reports the file.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace portalsim::io {

// Runs `read` in a forked child and returns the bytes it returned. An InputError thrown
// there is thrown here with its message, any other exception as std::runtime_error. A
// child that ends any other way (a signal, a sanitizer's report, an exit) is an InputError
// naming `path`: the file is damaged, or not one `what` can read. A child that spins is
// ended after 2 s of CPU time and 1 s more per 16 MiB of `path` (SIGXCPU). The child ends with _exit, so it flushes
// nothing the parent holds open.
std::string read_contained(const std::string& path, const std::string& what, const std::function<std::string()>& read);

// The bytes a child sends back: integers (8 bytes, little end first) and strings (their
// length, then their bytes), read back in the order written.
class Packer {
 public:
  void u64(uint64_t v);
  void str(const std::string& s);
  void strs(const std::vector<std::string>& v);
  std::string bytes;
};

class Unpacker {
 public:
  explicit Unpacker(const std::string& bytes) : bytes_(bytes) {}
  uint64_t u64();
  std::string str();
  std::vector<std::string> strs();
  bool done() const { return at_ == bytes_.size(); }

 private:
  const std::string& bytes_;
  size_t at_ = 0;
};

}  // namespace portalsim::io
