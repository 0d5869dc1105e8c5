// portalsim evaluate's numbers (host/evaluate/) on hand-worked cases: ROC points, AUC, Pd at
// Pfa, the log loss, the bootstrap, the decision-level fusions, the folds and the classifiers'
// determinism; and which regions hold a threat (cli/evaluate_data). The whole command, its
// files against scikit-learn and its refusals are in tests/evaluate_check.py (evaluate.python).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "cli/evaluate_data.h"
#include "evaluate/bootstrap.h"
#include "evaluate/classifiers.h"
#include "evaluate/fusion.h"
#include "evaluate/roc.h"
#include "scene/philox.h"
#include "support.h"

namespace portalsim::evaluate {
namespace {

// Threats score 0.9, 0.8, 0.4; non-threats 0.7, 0.3, 0.2, 0.1, 0.05.
const std::vector<double> kScore = {0.9, 0.7, 0.8, 0.3, 0.4, 0.2, 0.1, 0.05};
const std::vector<uint8_t> kLabel = {1, 0, 1, 0, 1, 0, 0, 0};

TEST(EvaluateRoc, PdAtPfaByHand) {
  const ScoreOrder o = order_scores(kScore);
  const RocSummary s = summarize(o, kLabel, nullptr, {0.0, 0.1, 0.2, 0.5});
  // Pfa 0: the thresholds 0.9 and 0.8 alarm on no non-threat: Pd 2/3 at 0.8.
  EXPECT_DOUBLE_EQ(s.pd[0].pd, 2.0 / 3);
  EXPECT_DOUBLE_EQ(s.pd[0].pfa, 0);
  EXPECT_DOUBLE_EQ(s.pd[0].threshold, 0.8);
  // Pfa 0.1: one non-threat of five is 0.2, over the target: still 2/3.
  EXPECT_DOUBLE_EQ(s.pd[1].pd, 2.0 / 3);
  // Pfa 0.2: threshold 0.4 alarms on every threat and on 0.7 alone.
  EXPECT_DOUBLE_EQ(s.pd[2].pd, 1);
  EXPECT_DOUBLE_EQ(s.pd[2].pfa, 0.2);
  EXPECT_DOUBLE_EQ(s.pd[2].threshold, 0.4);
  EXPECT_DOUBLE_EQ(s.pd[3].pd, 1);
  EXPECT_DOUBLE_EQ(s.pd[3].pfa, 0.2) << "the first point that reaches Pd 1, not a later one";
  // AUC: of the 15 (threat, non-threat) pairs, 14 are in order (0.4 < 0.7 is the one not).
  EXPECT_DOUBLE_EQ(s.auc, 14.0 / 15);
}

TEST(EvaluateRoc, CurvePointsByHand) {
  const RocCurve c = roc_curve(order_scores(kScore), kLabel);
  const std::vector<double> pfa = {0, 0, 0, 0.2, 0.2, 0.4, 0.6, 0.8, 1};
  const std::vector<double> pd = {0, 1.0 / 3, 2.0 / 3, 2.0 / 3, 1, 1, 1, 1, 1};
  ASSERT_EQ(c.pfa.size(), pfa.size());
  for (size_t i = 0; i < pfa.size(); ++i) {
    EXPECT_DOUBLE_EQ(c.pfa[i], pfa[i]) << i;
    EXPECT_DOUBLE_EQ(c.pd[i], pd[i]) << i;
  }
  EXPECT_TRUE(std::isinf(c.threshold[0]));
  EXPECT_DOUBLE_EQ(c.threshold[1], 0.9);
}

TEST(EvaluateRoc, TiesBetweenClassesCountHalf) {
  // Threats 1 and 0.5, non-threats 0.5 and 0: pairs in order 1 + 1 + 1, the tie 1/2.
  const std::vector<double> score = {1, 0.5, 0.5, 0};
  const std::vector<uint8_t> label = {1, 1, 0, 0};
  EXPECT_DOUBLE_EQ(summarize(order_scores(score), label, nullptr, {}).auc, 3.5 / 4);
  // The tied group is one point: Pd at Pfa 0 is 1/2 (the 0.5s alarm together).
  EXPECT_DOUBLE_EQ(summarize(order_scores(score), label, nullptr, {0.0}).pd[0].pd, 0.5);
}

TEST(EvaluateRoc, WeightsCountRowsAgain) {
  // Weights 2 on a row are that row twice.
  const std::vector<double> twice = {0.9, 0.7, 0.8, 0.3, 0.4, 0.2, 0.1, 0.05, 0.4};
  const std::vector<uint8_t> label2 = {1, 0, 1, 0, 1, 0, 0, 0, 1};
  const std::vector<uint32_t> w = {1, 1, 1, 1, 2, 1, 1, 1};
  const RocSummary a = summarize(order_scores(kScore), kLabel, &w, {0.0, 0.2});
  const RocSummary b = summarize(order_scores(twice), label2, nullptr, {0.0, 0.2});
  EXPECT_DOUBLE_EQ(a.auc, b.auc);
  EXPECT_DOUBLE_EQ(a.pd[0].pd, b.pd[0].pd);
  EXPECT_DOUBLE_EQ(a.pd[1].pd, b.pd[1].pd);
}

TEST(EvaluateRoc, LogLossIsTheDirectFormula) {
  const std::vector<double> p = {0.9, 0.2, 1.0, 0.0, 0.5};
  const std::vector<uint8_t> y = {1, 0, 0, 1, 1};
  const double eps = 1e-15;
  const double direct =
      -(std::log(0.9) + std::log(1 - 0.2) + std::log(1 - (1 - eps)) + std::log(eps) + std::log(0.5)) / 5;
  EXPECT_NEAR(log_loss(p, y), direct, 1e-12);
}

TEST(EvaluateBootstrap, IntervalsHoldTheEstimateAndRepeat) {
  // 400 rows: threats score higher on average.
  std::vector<double> score;
  std::vector<uint8_t> label;
  for (uint32_t i = 0; i < 400; ++i) {
    label.push_back(i % 3 == 0);
    score.push_back(uniform24(draw(7, i, 1, 0)[0]) + (label.back() ? 0.4 : 0.0));
  }
  const ScoreOrder o = order_scores(score);
  const std::vector<double> pfa = {0.01, 0.05, 0.1};
  const RocSummary point = summarize(o, label, nullptr, pfa);
  const BootstrapOptions opt{.seed = 3, .draws = 400, .threads = 2};
  const auto a = bootstrap({&o}, label, pfa, opt);
  EXPECT_LE(a[0].auc.lo, point.auc);
  EXPECT_GE(a[0].auc.hi, point.auc);
  EXPECT_LT(a[0].auc.lo, a[0].auc.hi);
  for (size_t k = 0; k < pfa.size(); ++k) {
    EXPECT_LE(a[0].pd[k].lo, point.pd[k].pd) << k;
    EXPECT_GE(a[0].pd[k].hi, point.pd[k].pd) << k;
  }
  // The same seed gives the same intervals on any thread count; another seed others.
  const auto b = bootstrap({&o}, label, pfa, {.seed = 3, .draws = 400, .threads = 1});
  EXPECT_EQ(a[0].auc.lo, b[0].auc.lo);
  EXPECT_EQ(a[0].auc.hi, b[0].auc.hi);
  EXPECT_EQ(a[0].pd[1].lo, b[0].pd[1].lo);
  const auto c = bootstrap({&o}, label, pfa, {.seed = 4, .draws = 400, .threads = 2});
  EXPECT_NE(a[0].auc.lo, c[0].auc.lo);
  // Stratified: each draw keeps the classes' counts.
  for (uint64_t d = 0; d < 10; ++d) {
    const std::vector<uint32_t> w = bootstrap_weights(label, 3, d);
    uint32_t pos = 0, neg = 0;
    for (size_t i = 0; i < w.size(); ++i) (label[i] ? pos : neg) += w[i];
    EXPECT_EQ(pos, 134u) << "draw " << d;
    EXPECT_EQ(neg, 266u) << "draw " << d;
  }
}

TEST(EvaluateBootstrap, QuantileIsLinearBetweenOrderStatistics) {
  EXPECT_DOUBLE_EQ(quantile({4, 1, 3, 2}, 0.5), 2.5);
  EXPECT_DOUBLE_EQ(quantile({4, 1, 3, 2}, 0.025), 1.075);
  EXPECT_DOUBLE_EQ(quantile({4, 1, 3, 2}, 1), 4);
}

TEST(EvaluateFusion, RulesOnAHandMadeCase) {
  // Rows: two non-threats, then two threats; three sensors.
  const std::vector<uint8_t> label = {0, 0, 1, 1};
  const std::vector<std::vector<double>> s = {{0.1, 0.2, 0.9, 0.15}, {0.3, 0.1, 0.2, 0.8}, {0.5, 0.6, 0.7, 0.05}};
  // Each row's per-sensor Pfa u: the share of non-threats scoring at least it.
  EXPECT_EQ(negative_exceedance(s[0], label), (std::vector<double>{1, 0.5, 0, 0.5}));
  EXPECT_EQ(negative_exceedance(s[1], label), (std::vector<double>{0.5, 1, 0.5, 0}));
  EXPECT_EQ(negative_exceedance(s[2], label), (std::vector<double>{1, 0.5, 0, 1}));
  EXPECT_EQ(decision_fusion(s, label, DecisionRule::any), (std::vector<double>{-0.5, -0.5, -0.0, -0.0}));
  EXPECT_EQ(decision_fusion(s, label, DecisionRule::all), (std::vector<double>{-1, -1, -0.5, -1}));
  EXPECT_EQ(decision_fusion(s, label, DecisionRule::majority), (std::vector<double>{-1, -0.5, -0.0, -0.5}));
  // At a common per-sensor Pfa of 0: OR alarms on both threats and no non-threat.
  const RocSummary any = summarize(order_scores(decision_fusion(s, label, DecisionRule::any)), label, nullptr, {0.0});
  EXPECT_DOUBLE_EQ(any.pd[0].pd, 1);
  // Of two sensors, majority is AND.
  const std::vector<std::vector<double>> two(s.begin(), s.begin() + 2);
  EXPECT_EQ(decision_fusion(two, label, DecisionRule::majority), decision_fusion(two, label, DecisionRule::all));
}

TEST(EvaluateFolds, StratifiedAndRepeatable) {
  std::vector<uint8_t> label;
  for (int i = 0; i < 103; ++i) label.push_back(i % 4 == 0);
  const std::vector<int> f = stratified_folds(label, 5, 9);
  EXPECT_EQ(f, stratified_folds(label, 5, 9));
  EXPECT_NE(f, stratified_folds(label, 5, 10));
  for (uint8_t cls : {0, 1}) {
    std::vector<int> count(5, 0);
    for (size_t i = 0; i < label.size(); ++i)
      if (label[i] == cls) ++count[static_cast<size_t>(f[i])];
    const auto [lo, hi] = std::minmax_element(count.begin(), count.end());
    EXPECT_LE(*hi - *lo, 1) << "class " << int(cls);
  }
}

// rows x cols uniform draws (Philox under seed, stream); every `period`-th row a threat, its
// column `signal` raised by `shift`.
Matrix draws(uint32_t rows, uint32_t cols, uint64_t seed, uint32_t stream, uint32_t period, uint32_t signal,
             double shift, std::vector<uint8_t>& label) {
  Matrix m;
  m.rows = rows;
  m.cols = cols;
  for (uint32_t r = 0; r < rows; ++r) {
    label.push_back(r % period == period - 1);
    for (uint32_t c = 0; c < cols; ++c)
      m.x.push_back(
          static_cast<float>(uniform24(draw(seed, r, stream, c)[0]) + (c == signal && label.back() ? shift : 0.0)));
  }
  return m;
}

TEST(EvaluateClassifiers, ScoresAreTheSameOnAnyThreadCountAndSeparateTheClasses) {
  std::vector<uint8_t> label;
  const Matrix m = draws(300, 4, 5, 2, 2, 0, 0.5, label);
  const std::vector<int> fold = stratified_folds(label, 5, 1);
  for (ClassifierKind k : {ClassifierKind::trees, ClassifierKind::logistic}) {
    const std::vector<CvJob> jobs = {{&m, &label, k}, {&m, &label, k}};
    const auto one = out_of_fold(jobs, fold, 5, 1, 1);
    const auto two = out_of_fold(jobs, fold, 5, 1, 2);
    EXPECT_EQ(one, two) << classifier_name(k);
    EXPECT_EQ(one[0], one[1]) << classifier_name(k);
    EXPECT_GT(summarize(order_scores(one[0]), label, nullptr, {}).auc, 0.8) << classifier_name(k);
  }
}

// A matrix of `rows` rows, row r being `row(r)`, and labels alternating 0, 1 into `label`.
Matrix rows_of(uint32_t rows, size_t cols, std::vector<uint8_t>& label,
               const std::function<std::vector<float>(uint32_t)>& row) {
  Matrix m;
  m.rows = rows;
  m.cols = cols;
  for (uint32_t r = 0; r < rows; ++r) {
    label.push_back(r % 2);
    const std::vector<float> v = row(r);
    m.x.insert(m.x.end(), v.begin(), v.end());
  }
  return m;
}

TEST(EvaluateClassifiers, QuantisationCutsAtTheTrainingRowsOnly) {
  // Column 0: 200 distinct values (the row number, reversed); column 1: 5 values and a
  // missing one; column 2: a constant.
  std::vector<uint8_t> label;
  const Matrix m = rows_of(200, 3, label, [](uint32_t r) {
    return std::vector<float>{static_cast<float>(200 - r), r % 7 == 6 ? NAN : static_cast<float>(r % 7), 1.5f};
  });
  const std::vector<int> fold = stratified_folds(label, 4, 3);
  const auto bins = quantise_folds(m, fold, 4, 2);
  ASSERT_EQ(bins.size(), 4u);
  EXPECT_EQ(bins, quantise_folds(m, fold, 4, 1));  // any thread count
  for (int f = 0; f < 4; ++f) {
    const std::vector<uint8_t>& b = bins[static_cast<size_t>(f)];
    std::vector<size_t> count(kTreeBins, 0);
    for (uint32_t r = 0; r < m.rows; ++r) {
      // Larger values, no smaller bins; kTreeBins bins of about equal counts.
      for (uint32_t s = 0; s < m.rows; ++s)
        EXPECT_TRUE(m.at(r, 0) <= m.at(s, 0) || b[r * 3] >= b[s * 3]) << r << " " << s;
      ASSERT_LT(b[r * 3], kTreeBins);
      if (fold[r] != f) ++count[b[r * 3]];
      // Few values: a bin each, in order; a missing value marked.
      EXPECT_EQ(b[r * 3 + 1], r % 7 == 6 ? kMissingBin : r % 7) << r;
      EXPECT_EQ(b[r * 3 + 2], 0);
    }
    for (size_t k = 0; k < count.size(); ++k) EXPECT_NEAR(count[k], 150.0 / kTreeBins, 1.0) << k;
  }
  // Fold 2's values move no cut of fold 2: every other row keeps its bin there; in the
  // folds that train on them, they do move cuts.
  Matrix moved = m;
  for (uint32_t r = 0; r < m.rows; ++r)
    if (fold[r] == 2) moved.x[r * 3] = static_cast<float>(1000 + r);
  const auto after = quantise_folds(moved, fold, 4, 1);
  size_t changed = 0;
  for (uint32_t r = 0; r < m.rows; ++r) {
    if (fold[r] == 2) continue;
    EXPECT_EQ(after[2][r * 3], bins[2][r * 3]) << r;
    changed += after[0][r * 3] != bins[0][r * 3];
  }
  EXPECT_GT(changed, 0u);
}

TEST(EvaluateClassifiers, AValueManyRowsShareTakesOneBinAndTheRestSplitTheOthers) {
  // 60% of the rows read 1 (as a metal zone does with nothing near it), the rest 400 values.
  std::vector<uint8_t> label;
  const Matrix m = rows_of(1000, 1, label, [](uint32_t r) {
    return std::vector<float>{r % 5 < 3 ? 1.0f : static_cast<float>(2 + r % 400)};
  });
  const std::vector<int> fold = stratified_folds(label, 5, 1);
  const std::vector<uint8_t> b = quantise_folds(m, fold, 5, 1)[0];
  std::vector<size_t> count(kTreeBins, 0);
  for (uint32_t r = 0; r < m.rows; ++r) ++count[b[r]];
  EXPECT_EQ(std::count(count.begin(), count.end(), size_t{0}), 0);  // every bin used
  EXPECT_EQ(count[0], 600u);                                        // the shared value alone
}

TEST(EvaluateClassifiers, AJobOnSomeColumnsScoresAsACopyOfThem) {
  std::vector<uint8_t> label;
  const Matrix m = draws(300, 6, 7, 3, 3, 4, 0.7, label);
  const std::vector<int> fold = stratified_folds(label, 5, 2);
  const std::vector<size_t> cols = {4, 1, 5};
  const Matrix copy = select_columns(m, cols);
  for (ClassifierKind k : {ClassifierKind::trees, ClassifierKind::logistic}) {
    // The columns of the shared matrix beside a job on all of it, as trees share its bins.
    const auto shared = out_of_fold({{&m, &label, k, &cols}, {&m, &label, k}}, fold, 5, 1, 2);
    const auto alone = out_of_fold({{&copy, &label, k}}, fold, 5, 1, 1);
    EXPECT_EQ(shared[0], alone[0]) << classifier_name(k);
    EXPECT_NE(shared[0], shared[1]) << classifier_name(k);
    EXPECT_GT(summarize(order_scores(shared[0]), label, nullptr, {}).auc, 0.8) << classifier_name(k);
  }
}

TEST(EvaluateClassifiers, TheReportStatesTheParametersTheBoostersGet) {
  for (ClassifierKind k : {ClassifierKind::trees, ClassifierKind::logistic}) {
    const std::string d = classifier_description(k);
    for (const auto& [key, value] : booster_parameters(k))
      EXPECT_NE(d.find(key + " " + value), std::string::npos) << key << " " << value << ": " << d;
  }
  const auto trees = booster_parameters(ClassifierKind::trees);
  EXPECT_NE(std::find(trees.begin(), trees.end(), std::pair<std::string, std::string>{"max_bin", "32"}), trees.end());
  EXPECT_EQ(kTreeBins, 32);
}

TEST(EvaluateRegions, AThreatIsInTheRegionsItsObjectsMake) {
  const Catalogue& c = test::catalogue();
  const ThreatRule both(c, "iron-rod & metal-plate");
  // rod in 1, plate in 2, tile in 3: a threat made by regions 1 and 2.
  const Scenario s = parse_object_list(c, {"iron-rod", "metal-plate", "cement-tile"});
  EXPECT_EQ(cli::region_threats(both, s, true), (std::array<uint8_t, kMaxRegions>{1, 1}));
  // The rod alone is no threat anywhere.
  EXPECT_EQ(cli::region_threats(both, parse_object_list(c, {"iron-rod"}), false), (std::array<uint8_t, kMaxRegions>{}));
  // Two plates and a rod: removing either plate leaves a threat; neither plate is needed, the rod is.
  const Scenario s2 = parse_object_list(c, {"iron-rod", "metal-plate", "metal-plate"});
  EXPECT_EQ(cli::region_threats(both, s2, true), (std::array<uint8_t, kMaxRegions>{1}));
  // A one-object rule: each gun is a threat on its own.
  const ThreatRule gun(c, "gun");
  EXPECT_EQ(cli::region_threats(gun, parse_object_list(c, {"none", "gun", "gun:v", "cement-tile"}), true),
            (std::array<uint8_t, kMaxRegions>{0, 1, 1, 0}));
}

}  // namespace
}  // namespace portalsim::evaluate
