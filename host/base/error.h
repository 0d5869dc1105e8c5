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

namespace portalsim {

// The machine lacks something the run needs (no OpenCL platform or device, PoCL's kernel
// cache not writable, no fp64): the user fixes it by installing or choosing otherwise.
class EnvironmentError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace portalsim
