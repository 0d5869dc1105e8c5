// Scores from classifiers by k-fold cross-validation: every row's score comes from a model
// that did not see it. The classifiers are XGBoost's (its C API, Debian libxgboost-dev):
// gradient-boosted trees, and logistic regression as XGBoost's linear booster with the
// logistic objective. Each model trains on one thread with fixed seeds, so scores are the
// same for any thread count and run to run.
//
// The trees see each fold's features quantised once (quantise_fold): every column cut into
// at most kTreeBins bins at the quantiles of that fold's training rows, the rows' bins handed
// to XGBoost as a quantile matrix, so no model sketches its data again. Every model of a
// fold that reads a column sees the same bins.
#pragma once
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace portalsim::evaluate {

enum class ClassifierKind { trees, logistic };
ClassifierKind parse_classifier(const std::string& name, const std::string& where);
const char* classifier_name(ClassifierKind k);
// The parameters its boosters get (XGBoosterSetParam's keys and values, besides nthread and
// seed), and its description for the report, made from them.
std::vector<std::pair<std::string, std::string>> booster_parameters(ClassifierKind k);
std::string classifier_description(ClassifierKind k);

// The trees' bins per column (XGBoost's max_bin), the one value the training and the report use.
inline constexpr int kTreeBins = 32;

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

// Fold f's bins of every row of `m` (training rows and test rows alike), row-major, each
// column cut at the quantiles of its values on the rows outside fold f: a column with at
// most kTreeBins distinct values there gets a bin per value, another kTreeBins bins of about
// equal counts. A value's bin is the number of cuts at or below it; kMissingBin marks NaN.
inline constexpr uint8_t kMissingBin = 255;
std::vector<std::vector<uint8_t>> quantise_folds(const Matrix& m, const std::vector<int>& fold, int k,
                                                 unsigned threads);

// One model's job: features and labels; each fold's model trains on the other folds.
struct CvJob {
  const Matrix* x = nullptr;
  const std::vector<uint8_t>* label = nullptr;
  ClassifierKind kind = ClassifierKind::trees;
  const std::vector<size_t>* columns = nullptr;  // the columns of x it reads; every one when null
};
// Out-of-fold probabilities of the positive class, one vector per job; the jobs' folds run
// on up to `threads` threads, each model on one, the costliest first. Tree jobs on one
// matrix share its quantisation (quantise_folds, once per fold).
std::vector<std::vector<double>> out_of_fold(const std::vector<CvJob>& jobs, const std::vector<int>& fold, int k,
                                             uint64_t seed, unsigned threads);

}  // namespace portalsim::evaluate
