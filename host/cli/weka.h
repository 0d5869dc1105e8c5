// WEKA's J48 (C4.5) under 10-fold cross-validation, as the thesis scored its data
// (chapter 6), run through Debian's weka package.
#pragma once
#include <optional>
#include <string>

namespace portalsim::cli {

// Accuracy in percent, or nothing (with `why`) when java or weka.jar is missing or
// WEKA fails.
std::optional<double> j48_cv_accuracy(const std::string& arff, std::string& why);

}  // namespace portalsim::cli
