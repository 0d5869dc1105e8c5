// WEKA's classifiers run through Debian's weka package, scored as the thesis scored its
// data (chapter 6): stratified cross-validation, or train on one set and test on another.
#pragma once
#include <optional>
#include <string>

namespace portalsim::cli {

// Accuracy in percent, or nothing (with `why`) when java or weka.jar is missing or
// WEKA fails.
std::optional<double> j48_cv_accuracy(const std::string& arff, std::string& why);

// Why WEKA cannot run here (weka.jar or java missing), or nothing when it can.
std::optional<std::string> weka_missing();

struct WekaScore {
  double correct_percent = 0;
  long misclassified = 0;
};

// `classifier` is WEKA's class name (weka.classifiers.trees.J48, ...), default settings.
// With `test` empty: `folds`-fold stratified cross-validation of `train` with `seed`;
// otherwise trained on `train` and scored on `test`. Nothing (with `why`) on failure.
std::optional<WekaScore> weka_score(const std::string& classifier, const std::string& train, const std::string& test,
                                    int folds, int seed, std::string& why);

}  // namespace portalsim::cli
