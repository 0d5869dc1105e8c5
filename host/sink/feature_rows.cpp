#include "sink/feature_rows.h"

#include <charconv>
#include <cmath>

namespace portalsim {

void append_number(std::string& out, float v) {
  // Fixed point through integers: several times faster than printf, and the same text
  // wherever it runs. What does not fit (no feature portalsim makes: a file read back may
  // hold anything) is written in the shortest form that reads back as the same float.
  const double scaled = static_cast<double>(v) * 10000.0;
  if (!(std::fabs(scaled) < 9.0e18)) {  // llround gives a long long: below 2^63 (9.2e18)
    char buf[64];
    const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
    (void)ec;
    out.append(buf, end);
    return;
  }
  long long q = std::llround(scaled);
  if (q < 0) {
    out.push_back('-');
    q = -q;
  }
  char buf[32];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, q / 10000);
  (void)ec;
  int frac = static_cast<int>(q % 10000);
  if (frac != 0) {
    *end++ = '.';
    int digits = 4;
    while (frac % 10 == 0) frac /= 10, --digits;
    for (int d = digits - 1; d >= 0; --d) end[d] = static_cast<char>('0' + frac % 10), frac /= 10;
    end += digits;
  }
  out.append(buf, end);
}

void append_feature_row(std::string& out, const BatchOutput& b, size_t i, bool threat) {
  const float* f = b.features_of(i);
  for (int k = 0; k < b.layout.image_features(); ++k) {
    append_number(out, f[k]);
    out.push_back(',');
  }
  const uint8_t* m = b.metal_of(i);
  for (int z = 0; z < b.layout.zones; ++z) {
    out += std::to_string(m[z]);
    out.push_back(',');
  }
  out += threat ? "positive\n" : "negative\n";
}

std::string feature_csv_header(const FeatureLayout& layout) {
  std::string h;
  for (const std::string& n : layout.names()) h += n + ",";
  return h + "class\n";
}

}  // namespace portalsim
