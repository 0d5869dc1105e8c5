#include "evaluate/classifiers.h"

#include <xgboost/c_api.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <numeric>

#include "base/error.h"
#include "base/parallel.h"
#include "scene/philox.h"

namespace portalsim::evaluate {

namespace {

// The folds' Philox stream (apart from the generator's streams by value).
constexpr uint32_t kStreamFolds = 0x464f4c44;  // "FOLD"

// The classifiers' parameters: set on the boosters and stated in the report from here.
constexpr int kTreeRounds = 50;
constexpr int kTreeDepth = 4;
constexpr double kTreeEta = 0.3;
constexpr int kLinearRounds = 100;
constexpr double kLinearEta = 0.5;
constexpr double kLinearLambda = 0.0001;

std::string number(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

void check(int rc, const char* what) {
  if (rc != 0) throw std::runtime_error(std::string("XGBoost: ") + what + ": " + XGBGetLastError());
}

// Owns an XGBoost matrix.
struct DMatrix {
  DMatrixHandle h = nullptr;
  DMatrix() = default;
  DMatrix(const std::vector<float>& x, size_t rows, size_t cols) {
    check(XGDMatrixCreateFromMat_omp(x.data(), rows, cols, std::nanf(""), &h, 1), "DMatrix");
  }
  ~DMatrix() { XGDMatrixFree(h); }
  DMatrix(const DMatrix&) = delete;
  DMatrix& operator=(const DMatrix&) = delete;
};

// A quantile matrix (XGBoost's QuantileDMatrix) of bin numbers 0..kTreeBins-1 as floats: its
// cuts come from `ref`, a matrix whose row b holds b in every column, so each bin number is
// a bin of its own and XGBoost sketches kTreeBins rows instead of the data.
struct QuantileData {
  const std::vector<float>* x = nullptr;
  size_t rows = 0, cols = 0;
  DMatrixHandle proxy = nullptr;
  bool given = false;
};
void quantile_reset(DataIterHandle h) { static_cast<QuantileData*>(h)->given = false; }
int quantile_next(DataIterHandle h) {
  auto* d = static_cast<QuantileData*>(h);
  if (d->given) return 0;
  d->given = true;
  const std::string array = R"({"data": [)" + std::to_string(reinterpret_cast<uintptr_t>(d->x->data())) +
                            R"(, true], "shape": [)" + std::to_string(d->rows) + ", " + std::to_string(d->cols) +
                            R"(], "typestr": "<f4", "version": 3})";
  check(XGProxyDMatrixSetDataDense(d->proxy, array.c_str()), "proxy data");
  return 1;
}
void quantile_matrix(DMatrix& out, const std::vector<float>& x, size_t rows, size_t cols) {
  std::vector<float> bins(static_cast<size_t>(kTreeBins) * cols);
  for (size_t b = 0; b < static_cast<size_t>(kTreeBins); ++b)
    std::fill_n(bins.begin() + static_cast<long>(b * cols), cols, static_cast<float>(b));
  const DMatrix ref(bins, kTreeBins, cols);
  DMatrix proxy;
  check(XGProxyDMatrixCreate(&proxy.h), "proxy");
  QuantileData data{&x, rows, cols, proxy.h, false};
  const std::string config = R"({"missing": NaN, "nthread": 1, "max_bin": )" + std::to_string(kTreeBins) + "}";
  check(
      XGQuantileDMatrixCreateFromCallback(&data, proxy.h, ref.h, quantile_reset, quantile_next, config.c_str(), &out.h),
      "quantile DMatrix");
}

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

// Trains on the rows outside fold f, writes the scores of fold f's rows into `out`. Trees
// read `bins` (fold f's quantisation of the job's matrix), the linear model the values.
void fit_fold(const CvJob& job, const std::vector<uint8_t>* bins, const std::vector<int>& fold, int f, uint64_t seed,
              std::vector<double>& out) {
  const Matrix& m = *job.x;
  std::vector<size_t> all;
  if (!job.columns) {
    all.resize(m.cols);
    std::iota(all.begin(), all.end(), size_t{0});
  }
  const std::vector<size_t>& cols = job.columns ? *job.columns : all;
  const bool trees = job.kind == ClassifierKind::trees;
  std::vector<float> train, test, y;
  std::vector<size_t> test_rows;
  for (size_t r = 0; r < m.rows; ++r) {
    std::vector<float>& dst = fold[r] == f ? test : train;
    for (size_t c : cols) {
      if (!trees) {
        dst.push_back(m.at(r, c));
        continue;
      }
      const uint8_t b = (*bins)[r * m.cols + c];
      dst.push_back(b == kMissingBin ? std::nanf("") : static_cast<float>(b));
    }
    if (fold[r] == f)
      test_rows.push_back(r);
    else
      y.push_back((*job.label)[r]);
  }
  if (!trees) standardize(train, y.size(), test, test_rows.size(), cols.size());
  DMatrix dtrain;
  if (trees)
    quantile_matrix(dtrain, train, y.size(), cols.size());
  else
    check(XGDMatrixCreateFromMat_omp(train.data(), y.size(), cols.size(), std::nanf(""), &dtrain.h, 1), "DMatrix");
  const DMatrix dtest(test, test_rows.size(), cols.size());
  check(XGDMatrixSetFloatInfo(dtrain.h, "label", y.data(), y.size()), "labels");
  Booster b(dtrain);
  b.set("nthread", "1");
  b.set("seed", std::to_string(seed & 0x7fffffff));
  for (const auto& [key, value] : booster_parameters(job.kind)) b.set(key.c_str(), value);
  const int rounds = trees ? kTreeRounds : kLinearRounds;
  for (int i = 0; i < rounds; ++i) check(XGBoosterUpdateOneIter(b.h, i, dtrain.h), "training");
  bst_ulong n = 0;
  const float* p = nullptr;
  check(XGBoosterPredict(b.h, dtest.h, 0, 0, 0, &n, &p), "prediction");
  if (n != test_rows.size()) throw std::runtime_error("XGBoost: prediction has the wrong length");
  for (size_t i = 0; i < test_rows.size(); ++i) out[test_rows[i]] = p[i];
}

// The cuts of sorted values `v`: see quantise_folds. Bins are filled greedily, each to the
// rows left over the bins left, so a value shared by many rows takes one bin and the others
// still split the rest (as XGBoost's sketch keeps its heavy values apart).
std::vector<float> cuts_of(const std::vector<float>& v) {
  std::vector<float> cuts;
  size_t distinct = v.empty() ? 0 : 1;
  for (size_t i = 1; i < v.size() && distinct <= static_cast<size_t>(kTreeBins); ++i) distinct += v[i] != v[i - 1];
  if (distinct <= static_cast<size_t>(kTreeBins)) {
    for (size_t i = 1; i < v.size(); ++i)
      if (v[i] != v[i - 1]) cuts.push_back(v[i]);
    return cuts;
  }
  size_t left = v.size(), bins_left = static_cast<size_t>(kTreeBins), in_bin = 0;
  for (size_t i = 0; i + 1 < v.size() && bins_left > 1; ++i) {
    ++in_bin;
    if (v[i + 1] != v[i] && in_bin * bins_left >= left) {
      cuts.push_back(v[i + 1]);
      left -= in_bin;
      in_bin = 0;
      --bins_left;
    }
  }
  return cuts;
}

}  // namespace

ClassifierKind parse_classifier(const std::string& name, const std::string& where) {
  if (name == "trees") return ClassifierKind::trees;
  if (name == "logistic") return ClassifierKind::logistic;
  throw InputError(where + ": \"" + name + "\" is not a classifier (trees or logistic)");
}

const char* classifier_name(ClassifierKind k) { return k == ClassifierKind::trees ? "trees" : "logistic"; }

std::vector<std::pair<std::string, std::string>> booster_parameters(ClassifierKind k) {
  if (k == ClassifierKind::trees)
    return {{"booster", "gbtree"},
            {"tree_method", "hist"},
            {"max_depth", std::to_string(kTreeDepth)},
            {"eta", number(kTreeEta)},
            {"max_bin", std::to_string(kTreeBins)},
            {"objective", "binary:logistic"}};
  // coord_descent: the linear booster's deterministic updater (shotgun races its threads).
  // XGBoost multiplies lambda by the rows: 0.4 on 4,000.
  return {{"booster", "gblinear"},           {"updater", "coord_descent"}, {"feature_selector", "cyclic"},
          {"lambda", number(kLinearLambda)}, {"eta", number(kLinearEta)},  {"objective", "binary:logistic"}};
}

std::string classifier_description(ClassifierKind k) {
  std::string params;
  for (const auto& [key, value] : booster_parameters(k)) params += ", " + key + " " + value;
  if (k == ClassifierKind::trees)
    return "gradient-boosted trees (XGBoost, " + std::to_string(kTreeRounds) + " rounds" + params +
           "; each column cut at the quantiles of the training fold's values, once per fold for every model)";
  return "logistic regression (XGBoost, " + std::to_string(kLinearRounds) + " rounds" + params +
         " (lambda times the rows, as XGBoost scales it); features standardised on each training fold)";
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

std::vector<std::vector<uint8_t>> quantise_folds(const Matrix& m, const std::vector<int>& fold, int k,
                                                 unsigned threads) {
  std::vector<std::vector<uint8_t>> bins(static_cast<size_t>(k), std::vector<uint8_t>(m.rows * m.cols, kMissingBin));
  parallel_for(m.cols, threads, [&](size_t begin, size_t end) {
    std::vector<std::pair<float, uint32_t>> sorted;  // (value, row)
    std::vector<float> train;
    for (size_t c = begin; c < end; ++c) {
      sorted.clear();
      for (uint32_t r = 0; r < m.rows; ++r)
        if (!std::isnan(m.at(r, c))) sorted.emplace_back(m.at(r, c), r);
      std::sort(sorted.begin(), sorted.end());
      for (int f = 0; f < k; ++f) {
        train.clear();
        for (const auto& [v, r] : sorted)
          if (fold[r] != f) train.push_back(v);
        const std::vector<float> cuts = cuts_of(train);
        size_t b = 0;  // the values ascend, so their bins do
        for (const auto& [v, r] : sorted) {
          while (b < cuts.size() && cuts[b] <= v) ++b;
          bins[static_cast<size_t>(f)][r * m.cols + c] = static_cast<uint8_t>(b);
        }
      }
    }
  });
  return bins;
}

std::vector<std::vector<double>> out_of_fold(const std::vector<CvJob>& jobs, const std::vector<int>& fold, int k,
                                             uint64_t seed, unsigned threads) {
  quiet_once();
  std::vector<std::vector<double>> out(jobs.size());
  for (size_t j = 0; j < jobs.size(); ++j) out[j].assign(jobs[j].x->rows, 0.0);
  // Each matrix that trees read, quantised once per fold.
  std::map<const Matrix*, std::vector<std::vector<uint8_t>>> bins;
  for (const CvJob& job : jobs)
    if (job.kind == ClassifierKind::trees && !bins.count(job.x)) bins[job.x] = quantise_folds(*job.x, fold, k, threads);
  // One task per (job, fold), the costliest first (columns times rounds), each taken by the
  // next free thread; a task writes only its fold's rows, so the order does not matter.
  const size_t tasks = jobs.size() * static_cast<size_t>(k);
  std::vector<size_t> order(tasks);
  std::iota(order.begin(), order.end(), size_t{0});
  const auto cost = [&](size_t t) {
    const CvJob& job = jobs[t / static_cast<size_t>(k)];
    const size_t cols = job.columns ? job.columns->size() : job.x->cols;
    return cols * static_cast<size_t>(job.kind == ClassifierKind::trees ? kTreeRounds : 1);
  };
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return cost(a) > cost(b); });
  std::atomic<size_t> next{0};
  const size_t workers = std::min<size_t>(tasks, std::max(1u, threads));
  parallel_for(workers, threads, [&](size_t begin, size_t end) {
    for (size_t w = begin; w < end; ++w)
      for (size_t i = next++; i < tasks; i = next++) {
        const size_t t = order[i], j = t / static_cast<size_t>(k);
        const int f = static_cast<int>(t % static_cast<size_t>(k));
        const std::vector<uint8_t>* b =
            jobs[j].kind == ClassifierKind::trees ? &bins.at(jobs[j].x)[static_cast<size_t>(f)] : nullptr;
        fit_fold(jobs[j], b, fold, f, seed, out[j]);
      }
  });
  return out;
}

}  // namespace portalsim::evaluate
