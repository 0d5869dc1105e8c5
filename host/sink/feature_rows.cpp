#include "sink/feature_rows.h"

#include <cmath>
#include <cstdio>

namespace portalsim {

void append_number(std::string& out, float v) {
  char buf[48];
  int len = std::snprintf(buf, sizeof buf, "%.4f", static_cast<double>(v));
  while (len > 0 && buf[len - 1] == '0') --len;
  if (len > 0 && buf[len - 1] == '.') --len;
  if (len == 2 && buf[0] == '-' && buf[1] == '0') len = 1, buf[0] = '0';  // "-0" -> "0"
  out.append(buf, static_cast<size_t>(len));
}

void append_feature_row(std::string& out, const BatchOutput& b, size_t i, bool threat) {
  const float* f = b.features_of(i);
  for (int k = 0; k < b.layout.image_features(); ++k) {
    append_number(out, f[k]);
    out.push_back(',');
  }
  const uint8_t* m = b.metal_of(i);
  for (int z = 0; z < kZones; ++z) {
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
