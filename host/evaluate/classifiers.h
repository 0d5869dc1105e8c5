// Scores from classifiers by k-fold cross-validation: every row's score comes from a model
// that did not see it. The classifiers are XGBoost's (its C API, Debian libxgboost-dev):
// gradient-boosted trees, and logistic regression as XGBoost's linear booster with the
// logistic objective. Each model trains on one thread with fixed seeds, so scores are the
// same for any thread count and run to run.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace portalsim::evaluate {

enum class ClassifierKind { trees, logistic };
ClassifierKind parse_classifier(const std::string& name, const std::string& where);
const char* classifier_name(ClassifierKind k);
// Its parameters, as the report states them.
std::string classifier_description(ClassifierKind k);

// A dense matrix of features, row-major; NaN is a missing value.
struct Matrix {
  size_t rows = 0, cols = 0;
  std::vector<float> x;
  float at(size_t r, size_t c) const { return x[r * cols + c]; }
};
// The columns `cols` of `m`.
Matrix select_columns(const Matrix& m, const std::vector<size_t>& cols);

// Stratified folds: the positives, then the negatives, each in an order drawn from Philox
// under `seed`, dealt to folds 0, 1, ..., k-1 in turn. Needs k >= 2.
std::vector<int> stratified_folds(const std::vector<uint8_t>& label, int k, uint64_t seed);

// One model's job: features and labels; each fold's model trains on the other folds.
struct CvJob {
  const Matrix* x = nullptr;
  const std::vector<uint8_t>* label = nullptr;
  ClassifierKind kind = ClassifierKind::trees;
};
// Out-of-fold probabilities of the positive class, one vector per job; the jobs' folds run
// on up to `threads` threads, each model on one.
std::vector<std::vector<double>> out_of_fold(const std::vector<CvJob>& jobs, const std::vector<int>& fold, int k,
                                             uint64_t seed, unsigned threads);

}  // namespace portalsim::evaluate
