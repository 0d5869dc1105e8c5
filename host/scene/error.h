// The one error type for bad input: its message names the file, line and field.
#pragma once
#include <stdexcept>
#include <string>

namespace portalsim {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace portalsim

namespace portalsim {

// Output could not be written (unwritable folder, full disk, a folder not empty).
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace portalsim
