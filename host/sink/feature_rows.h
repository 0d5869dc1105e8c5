// Feature rows as text: the block and region means, the metal zones and the class,
// formatted the same way by every table sink (CSV, ARFF) and by `simulate`.
#pragma once
#include <string>

#include "backend/backend.h"

namespace portalsim {

// Shortest fixed text of a mean: up to 4 decimals, trailing zeros dropped ("153.27").
void append_number(std::string& out, float v);
// One row, comma-separated, ending in "positive" or "negative" and a newline.
void append_feature_row(std::string& out, const BatchOutput& b, size_t i, bool threat);
// The CSV header: the layout's names and "class".
std::string feature_csv_header(const FeatureLayout& layout);

}  // namespace portalsim
