#include "io/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "base/error.h"

namespace portalsim::io {

namespace {

// Closes the descriptor on every path out.
struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

std::string kind_of(mode_t m) {
  if (S_ISDIR(m)) return "a folder";
  if (S_ISFIFO(m)) return "a FIFO";
  if (S_ISCHR(m) || S_ISBLK(m)) return "a device";
  if (S_ISSOCK(m)) return "a socket";
  return "not a regular file";
}

std::string size_text(size_t bytes) { return std::to_string(bytes >> 20) + " MiB"; }

// Length of the UTF-8 sequence at s[i], or 0 when it is not valid UTF-8 (overlong
// forms, surrogates and code points above U+10FFFF are invalid).
size_t utf8_length(std::string_view s, size_t i, uint32_t& cp) {
  const auto b = [&](size_t k) { return static_cast<unsigned char>(s[i + k]); };
  const unsigned char c = b(0);
  size_t n;
  if (c < 0x80) {
    cp = c;
    return 1;
  } else if ((c & 0xE0) == 0xC0) {
    n = 2, cp = c & 0x1F;
  } else if ((c & 0xF0) == 0xE0) {
    n = 3, cp = c & 0x0F;
  } else if ((c & 0xF8) == 0xF0) {
    n = 4, cp = c & 0x07;
  } else {
    return 0;
  }
  if (i + n > s.size()) return 0;
  for (size_t k = 1; k < n; ++k) {
    if ((b(k) & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (b(k) & 0x3F);
  }
  static constexpr uint32_t kMin[5] = {0, 0, 0x80, 0x800, 0x10000};
  if (cp < kMin[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
  return n;
}

// Checks bytes; `at(line, column)` names the place of a fault, `line_limit` the longest line.
template <class Fail>
void check_bytes(std::string_view text, Fail fail) {
  size_t line = 1, column = 1, line_start = 0;
  for (size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '\n') {
      ++line, column = 1, line_start = ++i;
      continue;
    }
    if (i - line_start >= kMaxLineBytes)
      fail(line, column, "line longer than " + std::to_string(kMaxLineBytes) + " bytes");
    if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') {
      ++i;
      continue;
    }
    uint32_t cp = 0;
    const size_t n = utf8_length(text, i, cp);
    if (n == 0)
      fail(
          line, column, "invalid UTF-8 (byte 0x" + [&] {
            char hex[8];
            std::snprintf(hex, sizeof hex, "%02X", c);
            return std::string(hex);
          }() + ")");
    if (cp == 0) fail(line, column, "NUL byte");
    if ((cp < 0x20 && cp != '\t') || (cp >= 0x7F && cp < 0xA0)) {
      char code[16];
      std::snprintf(code, sizeof code, "0x%02X", static_cast<unsigned>(cp));
      fail(line, column, std::string("control character ") + code);
    }
    if (cp == 0xFEFF) fail(line, column, "byte-order mark (U+FEFF) inside the text");
    i += n;
    ++column;
  }
}

}  // namespace

std::string where(const std::string& source, size_t line, size_t column) {
  return source + ":" + std::to_string(line) + ":" + std::to_string(column);
}

void check_regular_file(const std::string& path, const std::string& what, size_t cap) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0)
    throw InputError(path + ": cannot read the " + what + ": " + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) throw InputError(path + ": the " + what + " is " + kind_of(st.st_mode) + ", not a file");
  if (static_cast<unsigned long long>(st.st_size) > cap)
    throw InputError(path + ": the " + what + " is larger than " + size_text(cap));
}

int open_regular_file(const std::string& path, const std::string& what) {
  // O_NONBLOCK: opening a FIFO must not wait for a writer; fstat then refuses it.
  Fd f{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY)};
  if (f.fd < 0) throw InputError(path + ": cannot read the " + what + ": " + std::strerror(errno));
  struct stat st;
  if (::fstat(f.fd, &st) != 0) throw InputError(path + ": cannot read the " + what + ": " + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) throw InputError(path + ": the " + what + " is " + kind_of(st.st_mode) + ", not a file");
  return std::exchange(f.fd, -1);
}

std::string read_file(const std::string& path, const std::string& what, size_t cap) {
  Fd f{open_regular_file(path, what)};
  std::string out;
  char buf[1 << 16];
  for (;;) {
    const ssize_t n = ::read(f.fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw InputError(path + ": cannot read the " + what + ": " + std::strerror(errno));
    if (n == 0) break;
    if (out.size() + static_cast<size_t>(n) > cap)
      throw InputError(path + ": the " + what + " is larger than " + size_text(cap));
    out.append(buf, static_cast<size_t>(n));
  }
  return out;
}

std::string_view check_text(std::string_view text, const std::string& source, Bom bom) {
  if (text.substr(0, 3) == "\xEF\xBB\xBF") {
    if (bom == Bom::refuse)
      throw InputError(where(source, 1, 1) +
                       ": byte-order mark (BOM) not allowed here; save the file as UTF-8 without BOM");
    text.remove_prefix(3);
  }
  check_bytes(text, [&](size_t line, size_t column, const std::string& what) {
    throw InputError(where(source, line, column) + ": " + what);
  });
  return text;
}

void check_line(std::string_view line, const std::string& source, size_t lineno) {
  // Most lines are printable ASCII: nothing to decode.
  std::string_view body = line;
  if (body.ends_with('\n')) body.remove_suffix(body.ends_with("\r\n") ? 2 : 1);
  bool plain = body.size() < kMaxLineBytes;
  for (const char c : body) plain &= (c >= 0x20 && c < 0x7F) || c == '\t';
  if (plain) return;
  check_bytes(line, [&](size_t l, size_t column, const std::string& what) {
    throw InputError(where(source, lineno + l - 1, column) + ": " + what);
  });
}

std::string read_text_file(const std::string& path, const std::string& what, Bom bom) {
  const std::string raw = read_file(path, what, kMaxTextBytes);
  return std::string(check_text(raw, path, bom));
}

void check_flag_value(std::string_view value, const std::string& flag) {
  check_bytes(value, [&](size_t, size_t column, const std::string& what) {
    throw InputError(flag + ": character " + std::to_string(column) + ": " + what);
  });
  if (value.find('\n') != std::string_view::npos) throw InputError(flag + ": a line break is not allowed in a value");
}

uint64_t parse_u64(const std::string& text, const std::string& field) {
  const bool hex = text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
  std::string digits = hex ? text.substr(2) : text;
  while (digits.size() > 1 && digits[0] == '0') digits.erase(0, 1);
  const auto bad = [&]() {
    return InputError(field + ": \"" + text + "\" is not an unsigned 64-bit integer (0 to 18446744073709551615)");
  };
  if (digits.empty() || digits.size() > 20) throw bad();
  unsigned __int128 v = 0;
  for (char c : digits) {
    int d;
    if (c >= '0' && c <= '9')
      d = c - '0';
    else if (hex && c >= 'a' && c <= 'f')
      d = c - 'a' + 10;
    else if (hex && c >= 'A' && c <= 'F')
      d = c - 'A' + 10;
    else
      throw bad();
    v = v * (hex ? 16 : 10) + d;
    if (v > UINT64_MAX) throw bad();
  }
  return static_cast<uint64_t>(v);
}

}  // namespace portalsim::io
