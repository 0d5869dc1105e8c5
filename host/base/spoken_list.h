// Names joined as a sentence says them: "a", "a and b", "a, b and c" (or "... or c").
#pragma once
#include <string>
#include <string_view>
#include <vector>

namespace portalsim {

inline std::string spoken_list(const std::vector<std::string>& names, std::string_view last = " and ") {
  std::string s;
  for (size_t k = 0; k < names.size(); ++k) {
    if (k > 0) s += k + 1 == names.size() ? std::string(last) : std::string(", ");
    s += names[k];
  }
  return s;
}

}  // namespace portalsim
