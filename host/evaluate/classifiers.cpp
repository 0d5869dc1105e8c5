#include "evaluate/classifiers.h"

#include <xgboost/c_api.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <numeric>

#include "base/error.h"
#include "base/parallel.h"
#include "scene/philox.h"

namespace portalsim::evaluate {

namespace {

// The folds' Philox stream (apart from the generator's streams by value).
constexpr uint32_t kStreamFolds = 0x464f4c44;  // "FOLD"

constexpr int kTreeRounds = 50;
constexpr int kLinearRounds = 100;

void check(int rc, const char* what) {
  if (rc != 0) throw std::runtime_error(std::string("XGBoost: ") + what + ": " + XGBGetLastError());
}

// Owns XGBoost handles.
struct DMatrix {
  DMatrixHandle h = nullptr;
  DMatrix(const std::vector<float>& x, size_t rows, size_t cols) {
    check(XGDMatrixCreateFromMat_omp(x.data(), rows, cols, std::nanf(""), &h, 1), "DMatrix");
  }
  ~DMatrix() { XGDMatrixFree(h); }
  DMatrix(const DMatrix&) = delete;
  DMatrix& operator=(const DMatrix&) = delete;
};
struct Booster {
  BoosterHandle h = nullptr;
  explicit Booster(const DMatrix& train) { check(XGBoosterCreate(&train.h, 1, &h), "booster"); }
  ~Booster() { XGBoosterFree(h); }
  Booster(const Booster&) = delete;
  Booster& operator=(const Booster&) = delete;
  void set(const char* k, const std::string& v) { check(XGBoosterSetParam(h, k, v.c_str()), k); }
};

void quiet_once() {
  static std::once_flag once;
  std::call_once(once, [] { XGBSetGlobalConfig(R"({"verbosity": 0})"); });
}

// Each column's mean and sd over the training rows (logistic regression's coordinate
// descent wants features on one scale); missing values become the mean, 0 after scaling.
void standardize(std::vector<float>& train, size_t train_rows, std::vector<float>& test, size_t test_rows,
                 size_t cols) {
  for (size_t c = 0; c < cols; ++c) {
    double sum = 0, sum2 = 0, n = 0;
    for (size_t r = 0; r < train_rows; ++r) {
      const double v = train[r * cols + c];
      if (std::isnan(v)) continue;
      sum += v, sum2 += v * v, n += 1;
    }
    const double mean = n > 0 ? sum / n : 0, var = n > 0 ? sum2 / n - mean * mean : 0;
    const double sd = var > 1e-12 ? std::sqrt(var) : 1;
    for (auto [m, rows] : {std::pair{&train, train_rows}, std::pair{&test, test_rows}})
      for (size_t r = 0; r < rows; ++r) {
        float& v = (*m)[r * cols + c];
        v = std::isnan(v) ? 0.0f : static_cast<float>((v - mean) / sd);
      }
  }
}

// Trains on the rows outside fold f, writes the scores of fold f's rows into `out`.
void fit_fold(const CvJob& job, const std::vector<int>& fold, int f, uint64_t seed, std::vector<double>& out) {
  const Matrix& m = *job.x;
  std::vector<float> train, test, y;
  std::vector<size_t> test_rows;
  for (size_t r = 0; r < m.rows; ++r) {
    std::vector<float>& dst = fold[r] == f ? test : train;
    dst.insert(dst.end(), m.x.begin() + r * m.cols, m.x.begin() + (r + 1) * m.cols);
    if (fold[r] == f)
      test_rows.push_back(r);
    else
      y.push_back((*job.label)[r]);
  }
  if (job.kind == ClassifierKind::logistic) standardize(train, y.size(), test, test_rows.size(), m.cols);
  const DMatrix dtrain(train, y.size(), m.cols), dtest(test, test_rows.size(), m.cols);
  check(XGDMatrixSetFloatInfo(dtrain.h, "label", y.data(), y.size()), "labels");
  Booster b(dtrain);
  b.set("nthread", "1");
  b.set("seed", std::to_string(seed & 0x7fffffff));
  b.set("objective", "binary:logistic");
  int rounds = kTreeRounds;
  if (job.kind == ClassifierKind::trees) {
    b.set("booster", "gbtree");
    b.set("tree_method", "hist");
    b.set("max_depth", "4");
    b.set("eta", "0.3");
    b.set("max_bin", "32");
  } else {
    // coord_descent: the linear booster's deterministic updater (shotgun races its threads).
    b.set("booster", "gblinear");
    b.set("updater", "coord_descent");
    b.set("feature_selector", "cyclic");
    b.set("lambda", "0.0001");  // XGBoost multiplies it by the rows: 0.4 on 4,000
    b.set("eta", "0.5");
    rounds = kLinearRounds;
  }
  for (int i = 0; i < rounds; ++i) check(XGBoosterUpdateOneIter(b.h, i, dtrain.h), "training");
  bst_ulong n = 0;
  const float* p = nullptr;
  check(XGBoosterPredict(b.h, dtest.h, 0, 0, 0, &n, &p), "prediction");
  if (n != test_rows.size()) throw std::runtime_error("XGBoost: prediction has the wrong length");
  for (size_t i = 0; i < test_rows.size(); ++i) out[test_rows[i]] = p[i];
}

}  // namespace

ClassifierKind parse_classifier(const std::string& name, const std::string& where) {
  if (name == "trees") return ClassifierKind::trees;
  if (name == "logistic") return ClassifierKind::logistic;
  throw InputError(where + ": \"" + name + "\" is not a classifier (trees or logistic)");
}

const char* classifier_name(ClassifierKind k) { return k == ClassifierKind::trees ? "trees" : "logistic"; }

std::string classifier_description(ClassifierKind k) {
  if (k == ClassifierKind::trees)
    return "gradient-boosted trees (XGBoost gbtree, hist, " + std::to_string(kTreeRounds) +
           " rounds, max_depth 4, eta 0.2, max_bin 64, binary:logistic)";
  return "logistic regression (XGBoost gblinear, coord_descent, cyclic, " + std::to_string(kLinearRounds) +
         " rounds, eta 0.5, lambda 0.0001 (times the rows, as XGBoost scales it), binary:logistic; features "
         "standardised on each training fold)";
}

Matrix select_columns(const Matrix& m, const std::vector<size_t>& cols) {
  Matrix s;
  s.rows = m.rows;
  s.cols = cols.size();
  s.x.reserve(s.rows * s.cols);
  for (size_t r = 0; r < m.rows; ++r)
    for (size_t c : cols) s.x.push_back(m.at(r, c));
  return s;
}

std::vector<int> stratified_folds(const std::vector<uint8_t>& label, int k, uint64_t seed) {
  std::vector<int> fold(label.size(), 0);
  for (uint8_t cls : {uint8_t{1}, uint8_t{0}}) {
    std::vector<std::pair<uint32_t, uint32_t>> keyed;  // (draw, row)
    for (uint32_t r = 0; r < label.size(); ++r)
      if ((label[r] != 0) == (cls != 0)) keyed.emplace_back(draw(seed, r, kStreamFolds, 0)[0], r);
    std::sort(keyed.begin(), keyed.end());
    for (size_t i = 0; i < keyed.size(); ++i) fold[keyed[i].second] = static_cast<int>(i % static_cast<size_t>(k));
  }
  return fold;
}

std::vector<std::vector<double>> out_of_fold(const std::vector<CvJob>& jobs, const std::vector<int>& fold, int k,
                                             uint64_t seed, unsigned threads) {
  quiet_once();
  std::vector<std::vector<double>> out(jobs.size());
  for (size_t j = 0; j < jobs.size(); ++j) out[j].assign(jobs[j].x->rows, 0.0);
  const size_t tasks = jobs.size() * static_cast<size_t>(k);
  // One task per (job, fold), dealt one at a time so that a slow job does not hold a thread's chunk.
  parallel_for(std::min<size_t>(tasks, std::max(1u, threads)), threads, [&](size_t begin, size_t end) {
    const size_t workers = std::min<size_t>(tasks, std::max(1u, threads));
    for (size_t w = begin; w < end; ++w)
      for (size_t t = w; t < tasks; t += workers)
        fit_fold(jobs[t / k], fold, static_cast<int>(t % k), seed, out[t / k]);
  });
  return out;
}

}  // namespace portalsim::evaluate
