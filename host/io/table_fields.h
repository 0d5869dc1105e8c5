// The fields of one line of a CSV or ARFF table: the one reader of both formats' quoting,
// for every table portalsim reads (scenario lists, validate's feature tables, the tables
// the dataset card describes).
#pragma once
#include <cstddef>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace portalsim::io {

enum class Quoting {
  csv,   // RFC 4180: a field in "..." may hold commas and blanks; "" in it is one quote
  arff,  // WEKA: a field in '...' or "..." may hold commas and blanks; \ escapes the next character
};

// Splits `line` (without its line end) at the commas outside quotes into f[0..count),
// reusing f's strings, and returns count. Blanks (spaces, tabs) around a field are dropped,
// its quotes removed. Throws InputError "path:line: column k: why" for a quoted field not
// closed on its line, text after a closing quote, a quote inside an unquoted field, or a
// field longer than `max_bytes`.
size_t split_fields(std::string_view line, std::vector<std::string>& f, Quoting quoting, const std::string& path,
                    size_t line_number, size_t max_bytes = std::numeric_limits<size_t>::max());
std::vector<std::string> split_fields(std::string_view line, Quoting quoting, const std::string& path,
                                      size_t line_number);

// An ARFF "@attribute NAME TYPE" line (the keyword in any case): the name, quoted as a
// field is or a word up to the first blank, and the type, the rest with blanks trimmed.
// Throws InputError "path:line: @attribute: why" for a line without a name or a badly quoted one.
struct ArffAttribute {
  std::string name, type;
};
ArffAttribute arff_attribute(std::string_view line, const std::string& path, size_t line_number);

}  // namespace portalsim::io
