#include "evaluate/report.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace portalsim::evaluate {

namespace {

using nlohmann::json;

json interval(const Interval& i) { return json::array({i.lo, i.hi}); }

json scored_json(const Scored& s, const Options& o) {
  json j = {{"how", s.how}, {"auc", s.summary.auc}, {"auc_interval", interval(s.interval.auc)}};
  json pd = json::array();
  for (size_t k = 0; k < o.pfa.size(); ++k) {
    const PdAtPfa& p = s.summary.pd[k];
    pd.push_back({{"pfa_target", p.target},
                  {"pd", p.pd},
                  {"pd_interval", interval(s.interval.pd[k])},
                  {"pfa", p.pfa},
                  {"threshold", std::isinf(p.threshold) ? json("inf") : json(p.threshold)}});
  }
  j["pd_at_pfa"] = pd;
  return j;
}

std::string fixed(double v, int digits = 3) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", digits, v);
  return b;
}

std::string pct(double v) { return fixed(100 * v, 1) + "%"; }

std::string with_interval(const json& v, const json& i, bool percent) {
  const auto f = [&](const json& x) { return percent ? pct(x.get<double>()) : fixed(x.get<double>()); };
  return f(v) + " (" + f(i[0]) + "–" + f(i[1]) + ")";
}

}  // namespace

std::string number_text(double v) {
  char b[64];
  const auto r = std::to_chars(b, b + sizeof b, v);
  return std::string(b, r.ptr);
}

json report_json(const Dataset& d, const Evaluation& e, const Options& o, const json& about) {
  json r;
  r["data"] = about;
  r["rows"] = d.label.size();
  r["positives"] = std::count(d.label.begin(), d.label.end(), uint8_t{1});
  r["sensors"] = sensors_of(d);
  json cols = json::object();
  for (const std::string& s : sensors_of(d)) cols[s] = std::count(d.sensor.begin(), d.sensor.end(), s);
  r["sensor_columns"] = cols;
  r["method"] = {
      {"classifier", classifier_name(o.classifier)},
      {"classifier_parameters", classifier_description(o.classifier)},
      {"folds", o.folds},
      {"folds_how",
       "stratified: each class's rows in an order drawn from Philox4x32-10 under the seed, dealt to the "
       "folds in turn"},
      {"seed", o.seed},
      {"bootstrap_draws", o.bootstrap},
      {"bootstrap_how",
       "percentile bootstrap, 95%: each draw resamples the threats and the non-threats apart "
       "(stratified) with Philox4x32-10 under the seed; every score on the same draws; "
       "percentiles linear between order statistics. Decision-level fusions are bootstrapped "
       "with their per-sensor thresholds as set on the whole data"},
      {"pd_at_pfa_how",
       "the largest Pd among the ROC's operating points (thresholds at each distinct score) whose "
       "Pfa is at most the target; no interpolation"},
      {"auc_how", "trapezoid rule over the ROC's points (ties count half, the Mann-Whitney statistic)"},
      {"decision_fusion_how",
       "each sensor alarms when its score reaches the threshold at which a share p of the non-threats alarm (one "
       "common per-sensor Pfa p for every sensor); OR: any sensor alarms, AND: all, majority: more than half (of "
       "two sensors: both); p is swept to trace the fused ROC, and Pd at a target Pfa is the best Pd of a p whose "
       "fused Pfa is at most the target"},
      {"stacking_how",
       "logistic regression (XGBoost gblinear) on the logits of the sensors' out-of-fold scores, "
       "trained and scored on the same folds"},
      {"region_how",
       "per region, a classifier of 'a threat is in this region' on that region's mean, the blocks "
       "that overlap it and the metal zones; out-of-fold on the same folds"},
      {"log_loss_how",
       "mean over rows of -(y log p + (1-y) log(1-p)), p clipped to [1e-15, 1-1e-15], per region; "
       "the mean over regions is the Kaggle/DHS Passenger Screening Challenge's score; baseline: "
       "each region's share of threats as p"}};
  json entries = json::object();
  json order = json::array();
  for (const Scored& s : e.entries) {
    entries[s.name] = scored_json(s, o);
    order.push_back(s.name);
  }
  r["entries"] = entries;
  r["entry_order"] = order;
  json regions = json::array();
  for (const RegionResult& rr : e.regions) {
    json j = {{"name", rr.name},
              {"threats", rr.positives},
              {"log_loss", rr.log_loss},
              {"baseline_log_loss", rr.baseline_log_loss}};
    if (rr.scored) {
      const json s = scored_json(*rr.scored, o);
      j["auc"] = s["auc"];
      j["auc_interval"] = s["auc_interval"];
      j["pd_at_pfa"] = s["pd_at_pfa"];
    }
    regions.push_back(j);
  }
  r["regions"] = regions;
  if (!e.regions.empty())
    r["log_loss"] = {{"mean_over_regions", e.mean_log_loss}, {"baseline_mean_over_regions", e.baseline_mean_log_loss}};
  return r;
}

std::string report_markdown(const json& r) {
  std::ostringstream md;
  const json& m = r["method"];
  md << "# portalsim evaluate\n\n";
  md << "Data: `" << r["data"]["source"].get<std::string>() << "`, " << r["rows"].get<size_t>() << " scenarios, "
     << r["positives"].get<size_t>() << " threats";
  if (r["data"].contains("rule")) md << " (rule `" << r["data"]["rule"].get<std::string>() << "`)";
  md << ". Sensors and their feature columns: ";
  std::string cols;
  for (const auto& [s, n] : r["sensor_columns"].items())
    cols += (cols.empty() ? "" : ", ") + s + " " + std::to_string(n.get<size_t>());
  md << cols << ".\n\n";
  md << "Scores: " << m["folds"].get<int>() << "-fold cross-validation (" << m["folds_how"].get<std::string>()
     << ", seed " << m["seed"].get<uint64_t>() << "), " << m["classifier_parameters"].get<std::string>()
     << ". Intervals: " << m["bootstrap_how"].get<std::string>() << ", " << m["bootstrap_draws"].get<int>()
     << " draws.\n\n";
  md << "## Per sensor and fused\n\n| entry | AUC (95% interval) |";
  const json& first = r["entries"][r["entry_order"][0].get<std::string>()];
  for (const json& p : first["pd_at_pfa"]) md << " Pd at Pfa " << pct(p["pfa_target"].get<double>()) << " |";
  md << "\n|---|---|";
  for (size_t k = 0; k < first["pd_at_pfa"].size(); ++k) md << "---|";
  md << "\n";
  for (const json& name : r["entry_order"]) {
    const json& e = r["entries"][name.get<std::string>()];
    md << "| " << name.get<std::string>() << " | " << with_interval(e["auc"], e["auc_interval"], false) << " |";
    for (const json& p : e["pd_at_pfa"]) md << " " << with_interval(p["pd"], p["pd_interval"], true) << " |";
    md << "\n";
  }
  md << "\nWhat each entry is:\n\n";
  for (const json& name : r["entry_order"])
    md << "- `" << name.get<std::string>() << "`: " << r["entries"][name.get<std::string>()]["how"].get<std::string>()
       << "\n";
  md << "\nPd at Pfa: " << m["pd_at_pfa_how"].get<std::string>() << ". AUC: " << m["auc_how"].get<std::string>()
     << ". Decision-level fusion: " << m["decision_fusion_how"].get<std::string>() << ".\n\n";
  if (!r["regions"].empty()) {
    // The regions' table shows one target: the second (5% by default), or the only one.
    const size_t k = std::min<size_t>(1, first["pd_at_pfa"].size() - 1);
    md << "## Per region: a threat in this region\n\n"
       << m["region_how"].get<std::string>() << ". Labels: " << r["data"]["region_labels"].get<std::string>()
       << ".\n\n| region | threats | AUC | Pd at Pfa " << pct(first["pd_at_pfa"][k]["pfa_target"].get<double>())
       << " (achieved Pfa) | log loss | baseline |\n|---|---|---|---|---|---|\n";
    for (const json& g : r["regions"]) {
      md << "| " << g["name"].get<std::string>() << " | " << g["threats"].get<size_t>() << " | ";
      if (g.contains("auc")) {
        const json& p = g["pd_at_pfa"][k];
        md << with_interval(g["auc"], g["auc_interval"], false) << " | "
           << with_interval(p["pd"], p["pd_interval"], true) << " (" << pct(p["pfa"].get<double>()) << ") | ";
      } else {
        md << "- | - | ";
      }
      md << fixed(g["log_loss"].get<double>(), 4) << " | " << fixed(g["baseline_log_loss"].get<double>(), 4) << " |\n";
    }
    md << "\nMean log loss over regions (" << m["log_loss_how"].get<std::string>()
       << "): " << fixed(r["log_loss"]["mean_over_regions"].get<double>(), 4) << ", baseline "
       << fixed(r["log_loss"]["baseline_mean_over_regions"].get<double>(), 4) << ".\n\n";
  }
  md << "## Files\n\n- `scores.csv`: every row's label, fold and out-of-fold scores (each entry, and each "
        "region's label and probability)\n- `roc.csv`: each entry's ROC points\n- `report.json`: every number "
        "above\n";
  if (r.contains("plots"))
    for (const json& p : r["plots"]) md << "\n![" << p.get<std::string>() << "](" << p.get<std::string>() << ")\n";
  return md.str();
}

std::string scores_csv(const Dataset& d, const Evaluation& e) {
  std::string s = "row,label,fold";
  const auto field = [&s](const std::string& text) {
    s.push_back(',');
    s.append(text);
  };
  for (const Scored& x : e.entries) field(x.name);
  for (const RegionResult& rr : e.regions) {
    field(rr.name + "_label");
    field(rr.name + "_probability");
  }
  s.push_back('\n');
  for (size_t i = 0; i < d.label.size(); ++i) {
    s.append(std::to_string(i));
    field(std::to_string(d.label[i]));
    field(std::to_string(e.fold[i]));
    for (const Scored& x : e.entries) field(number_text(x.score[i]));
    for (size_t r = 0; r < e.regions.size(); ++r) {
      field(std::to_string(d.regions[r].label[i]));
      field(number_text(e.regions[r].probability[i]));
    }
    s.push_back('\n');
  }
  return s;
}

std::string roc_csv(const Dataset& d, const Evaluation& e) {
  std::string s = "entry,pfa,pd,threshold\n";
  for (const Scored& x : e.entries) {
    const RocCurve c = roc_curve(x.order, d.label);
    for (size_t i = 0; i < c.pfa.size(); ++i)
      s += x.name + "," + number_text(c.pfa[i]) + "," + number_text(c.pd[i]) + "," +
           (std::isinf(c.threshold[i]) ? std::string("inf") : number_text(c.threshold[i])) + "\n";
  }
  return s;
}

}  // namespace portalsim::evaluate
