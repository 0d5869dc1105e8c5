#include "evaluate/evaluation.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "base/error.h"
#include "evaluate/fusion.h"

namespace portalsim::evaluate {

namespace {

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

Scored scored(std::string name, std::string how, std::vector<double> score, const std::vector<uint8_t>& label,
              const Options& o) {
  Scored s;
  s.name = std::move(name);
  s.how = std::move(how);
  s.score = std::move(score);
  s.order = order_scores(s.score);
  s.summary = summarize(s.order, label, nullptr, o.pfa);
  return s;
}

// The bootstrap intervals of `scores`, all over `label`.
void add_intervals(std::vector<Scored*> scores, const std::vector<uint8_t>& label, const Options& o) {
  std::vector<const ScoreOrder*> orders;
  for (const Scored* s : scores) orders.push_back(&s->order);
  const auto intervals = bootstrap(orders, label, o.pfa, {.seed = o.seed, .draws = o.bootstrap, .threads = o.threads});
  for (size_t i = 0; i < scores.size(); ++i) scores[i]->interval = intervals[i];
}

float logit(double p) {
  const double q = std::clamp(p, 1e-6, 1 - 1e-6);
  return static_cast<float>(std::log(q / (1 - q)));
}

}  // namespace

std::vector<std::string> sensors_of(const Dataset& d) {
  std::vector<std::string> s;
  for (const std::string& name : d.sensor)
    if (std::find(s.begin(), s.end(), name) == s.end()) s.push_back(name);
  return s;
}

Evaluation run_evaluation(const Dataset& d, const Options& o) {
  const size_t positives = static_cast<size_t>(std::count(d.label.begin(), d.label.end(), uint8_t{1}));
  const size_t negatives = d.label.size() - positives;
  if (positives < static_cast<size_t>(o.folds) || negatives < static_cast<size_t>(o.folds))
    throw InputError(d.source + ": field 'class': " + std::to_string(positives) + " threats and " +
                     std::to_string(negatives) + " non-threats; each class needs at least as many rows as the " +
                     std::to_string(o.folds) + " folds");
  Evaluation e;
  e.fold = stratified_folds(d.label, o.folds, o.seed);
  const std::vector<std::string> sensors = sensors_of(d);

  // Per sensor, then all features, in one pool of fits, each on its columns of d.x.
  std::vector<std::vector<size_t>> sensor_columns;
  for (const std::string& s : sensors) {
    std::vector<size_t> cols;
    for (size_t c = 0; c < d.sensor.size(); ++c)
      if (d.sensor[c] == s) cols.push_back(c);
    sensor_columns.push_back(cols);
  }
  std::vector<CvJob> jobs;
  for (const std::vector<size_t>& cols : sensor_columns) jobs.push_back({&d.x, &d.label, o.classifier, &cols});
  jobs.push_back({&d.x, &d.label, o.classifier});
  // The regions' models, on their own labels.
  std::vector<size_t> region_job(d.regions.size(), SIZE_MAX);
  for (size_t r = 0; r < d.regions.size(); ++r) {
    const auto& reg = d.regions[r];
    const size_t pos = static_cast<size_t>(std::count(reg.label.begin(), reg.label.end(), uint8_t{1}));
    if (pos == 0 || pos == reg.label.size()) continue;
    region_job[r] = jobs.size();
    jobs.push_back({&d.x, &reg.label, o.classifier, &reg.columns});
  }
  auto t0 = std::chrono::steady_clock::now();
  std::vector<std::vector<double>> oof = out_of_fold(jobs, e.fold, o.folds, o.seed, o.threads);
  // Stacking: a logistic regression on the sensors' out-of-fold scores (as logits), itself
  // cross-validated on the same folds.
  std::vector<double> stacked;
  if (sensors.size() > 1) {
    Matrix m;
    m.rows = d.label.size();
    m.cols = sensors.size();
    for (size_t r = 0; r < m.rows; ++r)
      for (size_t s = 0; s < sensors.size(); ++s) m.x.push_back(logit(oof[s][r]));
    stacked = out_of_fold({{&m, &d.label, ClassifierKind::logistic}}, e.fold, o.folds, o.seed, o.threads)[0];
  }
  e.timing.training = since(t0);

  const std::string cv = std::to_string(o.folds) + "-fold out-of-fold " + classifier_name(o.classifier);
  for (size_t s = 0; s < sensors.size(); ++s)
    e.entries.push_back(scored(sensors[s], cv + " score on the " + sensors[s] + " features", oof[s], d.label, o));
  e.entries.push_back(
      scored("fused_features", cv + " score on every sensor's features together", oof[sensors.size()], d.label, o));
  if (sensors.size() > 1) {
    std::vector<std::vector<double>> per(oof.begin(), oof.begin() + static_cast<long>(sensors.size()));
    for (DecisionRule rule : {DecisionRule::any, DecisionRule::all, DecisionRule::majority})
      e.entries.push_back(scored(std::string("fused_") + rule_name(rule),
                                 std::string(rule_name(rule)) +
                                     " of the sensors' alarms, each sensor's threshold at one common per-sensor Pfa",
                                 decision_fusion(per, d.label, rule), d.label, o));
    e.entries.push_back(scored("fused_stacking",
                               "logistic regression on the sensors' out-of-fold scores (logits), " +
                                   std::to_string(o.folds) + "-fold out-of-fold",
                               stacked, d.label, o));
  }

  t0 = std::chrono::steady_clock::now();
  std::vector<Scored*> all;
  for (Scored& s : e.entries) all.push_back(&s);
  add_intervals(all, d.label, o);
  double sum = 0, base = 0;
  for (size_t r = 0; r < d.regions.size(); ++r) {
    const auto& reg = d.regions[r];
    RegionResult rr;
    rr.name = reg.name;
    rr.positives = static_cast<size_t>(std::count(reg.label.begin(), reg.label.end(), uint8_t{1}));
    const double share = static_cast<double>(rr.positives) / static_cast<double>(reg.label.size());
    rr.baseline_log_loss = log_loss(std::vector<double>(reg.label.size(), share), reg.label);
    if (region_job[r] != SIZE_MAX) {
      rr.probability = oof[region_job[r]];
      rr.scored = scored(reg.name, cv + " score for a threat in " + reg.name, rr.probability, reg.label, o);
      add_intervals({&*rr.scored}, reg.label, o);
    } else {
      rr.probability.assign(reg.label.size(), share);
    }
    rr.log_loss = log_loss(rr.probability, reg.label);
    sum += rr.log_loss;
    base += rr.baseline_log_loss;
    e.regions.push_back(std::move(rr));
  }
  if (!d.regions.empty()) {
    e.mean_log_loss = sum / static_cast<double>(d.regions.size());
    e.baseline_mean_log_loss = base / static_cast<double>(d.regions.size());
  }
  e.timing.bootstrap = since(t0);
  return e;
}

}  // namespace portalsim::evaluate
