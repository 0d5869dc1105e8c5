// Every file portalsim reads comes in through here: regular files only (a FIFO, a device
// or a folder is refused without blocking), at most a documented size, and text checked
// for bytes none of our formats allow before any parser sees it.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace portalsim::io {

inline constexpr size_t kMaxTextBytes = 64u << 20;    // catalogue, spec, metal.txt (a scenario list streams)
inline constexpr size_t kMaxImageBytes = 256u << 20;  // one image file
inline constexpr size_t kMaxLineBytes = 64u << 10;    // one line of any text file

// "file:line:column" (column in characters, 1-based).
std::string where(const std::string& source, size_t line, size_t column);

// The whole file, or InputError naming it: missing, not a regular file, unreadable, or
// larger than `cap` bytes. `what` says what the file is for ("spec file").
std::string read_file(const std::string& path, const std::string& what, size_t cap);

// The file opened for reading (a descriptor the caller closes), or InputError as
// read_file gives, for files read as a stream rather than whole.
int open_regular_file(const std::string& path, const std::string& what);

// Throws InputError unless `path` names a regular file of at most `cap` bytes.
void check_regular_file(const std::string& path, const std::string& what, size_t cap);

enum class Bom { refuse, skip };

// Checks text: valid UTF-8, no NUL or other control byte but tab and line ends (LF or
// CRLF), no line over kMaxLineBytes. A UTF-8 BOM at the start is refused or skipped.
// Returns the text without the BOM. Throws InputError naming source, line and column.
std::string_view check_text(std::string_view text, const std::string& source, Bom bom);

// check_text's checks for one line of a longer text, read a piece at a time: `line` (with
// its line end, where it has one) is line `lineno` of `source`.
void check_line(std::string_view line, const std::string& source, size_t lineno);

// read_file, then check_text.
std::string read_text_file(const std::string& path, const std::string& what, Bom bom);

// A value given on the command line: the same byte rules as files, at most
// kMaxLineBytes. Throws InputError starting with `flag` (a usage error).
void check_flag_value(std::string_view value, const std::string& flag);

// A decimal or 0x-hexadecimal unsigned 64-bit integer; throws InputError naming `field`.
uint64_t parse_u64(const std::string& text, const std::string& field);

}  // namespace portalsim::io
