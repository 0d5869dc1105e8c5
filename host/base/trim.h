// Text without the blanks (spaces, tabs, carriage returns) at its ends.
#pragma once
#include <string>

namespace portalsim {

inline std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r");
  return a == std::string::npos ? "" : s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

}  // namespace portalsim
