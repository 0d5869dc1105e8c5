// WEKA's classifiers run through Debian's weka package, scored as the thesis scored its
// data (chapter 6): stratified cross-validation, or train on one set and test on others.
#pragma once
#include <optional>
#include <string>
#include <vector>

namespace portalsim::cli {

// Why WEKA cannot run here (weka.jar or java missing), or nothing when it can.
std::optional<std::string> weka_missing();

// tools/Weka.java (embedded), written into the folder `dir`, and the command that runs it
// with WEKA's jar and a heap of `heap` ("4g"), to which its arguments are appended.
std::string weka_command(const std::string& dir, const char* heap);

struct WekaScore {
  long correct = 0;
  long misclassified = 0;
  double percent() const { return 100.0 * static_cast<double>(correct) / static_cast<double>(correct + misclassified); }
};

// A classifier (j48, svm or mlp; WEKA's default settings) trained on the ARFF `train` and
// scored on each of `tests`; with none, `folds`-fold stratified cross-validation of `train`
// seeded `seed`, as WEKA's command line `-x folds -s seed` makes it.
struct WekaJob {
  std::string classifier;
  std::string train;
  std::vector<std::string> tests;
  int folds = 10;
  long seed = 1;
};

// All `jobs` in one JVM (tools/Weka.java): entry j holds job j's score on each of its tests,
// or its cross-validation's alone. Nothing (with `why`) when WEKA cannot run or fails.
std::optional<std::vector<std::vector<WekaScore>>> weka_scores(const std::vector<WekaJob>& jobs, std::string& why);

}  // namespace portalsim::cli
