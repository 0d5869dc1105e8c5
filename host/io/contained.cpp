#include "io/contained.h"

#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <stdexcept>

#include "base/error.h"

// Set by a sanitizer's runtime, absent otherwise: under libFuzzer, its callback would dump
// the input as a crash of the fuzzer, when only the child died.
extern "C" void __sanitizer_set_death_callback(void (*)(void)) __attribute__((weak));

namespace portalsim::io {

namespace {

bool write_all(int fd, const char* p, size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    p += w;
    n -= static_cast<size_t>(w);
  }
  return true;
}

// CPU seconds a child may use: 2, and 1 more per 16 MiB of the file. Reading a data.h5's
// layout takes milliseconds, and 16 MiB of its rows (gzip) a tenth of a second; libhdf5
// spins for ever on some damaged files (tests/fuzz/crashes/h5/libhdf5-spins.h5), and
// SIGXCPU then ends the child.
rlim_t cpu_seconds(const std::string& path) {
  struct stat st {};
  const uint64_t bytes = ::stat(path.c_str(), &st) == 0 ? static_cast<uint64_t>(st.st_size) : 0;
  return static_cast<rlim_t>(2 + (bytes >> 24));
}

[[noreturn]] void child(int fd, rlim_t cpu_limit, const std::function<std::string()>& read) {
  // A crash ends the child with its signal, whatever handlers the parent set.
  for (int s : {SIGSEGV, SIGBUS, SIGABRT, SIGFPE, SIGILL, SIGXCPU}) std::signal(s, SIG_DFL);
  const rlimit cpu{cpu_limit, cpu_limit + 1};
  ::setrlimit(RLIMIT_CPU, &cpu);
  if (__sanitizer_set_death_callback) __sanitizer_set_death_callback(nullptr);
  std::string out;
  try {
    out = "D" + read();
  } catch (const InputError& e) {
    out = std::string("E") + e.what();
  } catch (const std::exception& e) {
    out = std::string("X") + e.what();
  } catch (...) {
    out = "X(an exception of no known type)";
  }
  ::_exit(write_all(fd, out.data(), out.size()) ? 0 : 3);
}

std::string how_it_ended(int status) {
  if (WIFSIGNALED(status)) {
    const int s = WTERMSIG(status);
    const char* name = ::strsignal(s);
    return "signal " + std::to_string(s) + (name ? std::string(", ") + name : "");
  }
  if (WIFEXITED(status)) return "exit status " + std::to_string(WEXITSTATUS(status));
  return "status " + std::to_string(status);
}

}  // namespace

std::string read_contained(const std::string& path, const std::string& what, const std::function<std::string()>& read) {
  const rlim_t cpu_limit = cpu_seconds(path);
  int fds[2];
  if (::pipe(fds) != 0) throw std::runtime_error("cannot make a pipe: " + std::string(std::strerror(errno)));
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw std::runtime_error("cannot fork to read " + path + ": " + std::string(std::strerror(errno)));
  }
  if (pid == 0) {
    ::close(fds[0]);
    child(fds[1], cpu_limit, read);
  }
  ::close(fds[1]);
  std::string got;
  char buf[1 << 16];
  for (;;) {
    const ssize_t r = ::read(fds[0], buf, sizeof buf);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) break;
    got.append(buf, static_cast<size_t>(r));
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0 && !got.empty()) {
    const std::string body = got.substr(1);
    if (got[0] == 'D') return body;
    if (got[0] == 'E') throw InputError(body);
    if (got[0] == 'X') throw std::runtime_error(body);
  }
  throw InputError(path + ": " + what + " died reading it (" + how_it_ended(status) +
                   "): the file is damaged, or not one portalsim wrote");
}

void Packer::u64(uint64_t v) {
  for (int k = 0; k < 8; ++k) bytes.push_back(static_cast<char>((v >> (8 * k)) & 0xFF));
}

void Packer::str(const std::string& s) {
  u64(s.size());
  bytes += s;
}

void Packer::strs(const std::vector<std::string>& v) {
  u64(v.size());
  for (const std::string& s : v) str(s);
}

uint64_t Unpacker::u64() {
  if (bytes_.size() - at_ < 8) throw std::runtime_error("a contained reader sent back too few bytes");
  uint64_t v = 0;
  for (int k = 0; k < 8; ++k) v |= uint64_t(static_cast<unsigned char>(bytes_[at_ + k])) << (8 * k);
  at_ += 8;
  return v;
}

std::string Unpacker::str() {
  const uint64_t n = u64();
  if (bytes_.size() - at_ < n) throw std::runtime_error("a contained reader sent back too few bytes");
  std::string s = bytes_.substr(at_, n);
  at_ += n;
  return s;
}

std::vector<std::string> Unpacker::strs() {
  const uint64_t n = u64();
  std::vector<std::string> v;
  for (uint64_t k = 0; k < n; ++k) v.push_back(str());
  return v;
}

}  // namespace portalsim::io
