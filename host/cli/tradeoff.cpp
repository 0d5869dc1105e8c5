// portalsim tradeoff: one scenario set through every fidelity tier and the fp64
// reference of each sensor model; throughput, error and the effect on a classifier, as
// JSON, CSV and a plot.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <utility>

#include "backend/compare.h"
#include "backend/opencl/noise_draws.h"
#include "backend/opencl/opencl_backend.h"
#include "backend/reference/draws.h"
#include "base/embedded.h"
#include "base/error.h"
#include "cli/commands.h"
#include "cli/common.h"
#include "cli/weka.h"
#include "io/input_file.h"
#include "plan/knobs.h"
#include "scene/generator.h"
#include "scene/philox.h"
#include "sink/sinks.h"
#include "sink/staging.h"

namespace portalsim {
namespace cli {

namespace {

using Clock = std::chrono::steady_clock;
using nlohmann::json;

struct TradeoffOptions {
  CommonOptions common;
  uint64_t count = 2000;
  std::string out = "tradeoff";
  ModelSettings model;
  std::string models = "thesis,physics";
  bool classifier = true;
  bool plot = true;
  double timed_seconds = 0.3;  // each timed pass's least length
};

Plan images_plan(const ModelSettings& m) {
  Plan p;
  p.model = m;
  return p;
}
Plan features_plan(const ModelSettings& m) {
  Plan p;
  p.model = m;
  p.images = 0;
  return p;
}

// Runs `batch` through `backend` in chunks; returns the outputs joined and the median
// rate (scenarios/s) over three timed passes of at least `min_seconds` each.
struct Timed {
  BatchOutput out;
  double rate = 0;
};

SceneBatch slice(const SceneBatch& b, size_t first, size_t n) {
  SceneBatch s(b.regions);
  s.first_index = b.first_index + first;
  s.subject.assign(b.subject.begin() + first, b.subject.begin() + first + n);
  s.objects.assign(b.objects.begin() + first * b.regions, b.objects.begin() + (first + n) * b.regions);
  s.label.assign(b.label.begin() + first, b.label.begin() + first + n);
  return s;
}

Timed run_timed(Backend& backend, const SceneBatch& batch, const Plan& plan, size_t chunk, double min_seconds) {
  Timed t;
  BatchOutput part;
  for (size_t first = 0; first < batch.size(); first += chunk) {
    backend.run(slice(batch, first, std::min(chunk, batch.size() - first)), plan, part);
    append_output(t.out, part);
  }
  std::vector<double> rates;
  for (int pass = 0; pass < 3; ++pass) {
    size_t done = 0;
    const auto t0 = Clock::now();
    double elapsed = 0;
    do {
      for (size_t first = 0; first < batch.size(); first += chunk) {
        const size_t n = std::min(chunk, batch.size() - first);
        backend.run(slice(batch, first, n), plan, part);
        done += n;
      }
      elapsed = std::chrono::duration<double>(Clock::now() - t0).count();
    } while (elapsed < min_seconds);
    rates.push_back(done / elapsed);
  }
  std::sort(rates.begin(), rates.end());
  t.rate = rates[1];
  return t;
}

void write_arff(const std::string& dir, const std::string& name, const SceneBatch& scenes, const BatchOutput& out,
                const Catalogue& cat) {
  SinkContext ctx;
  ctx.dir = dir;
  ctx.cat = &cat;
  ctx.layout = out.layout;
  ctx.rows = scenes.size();
  auto sink = make_table_sink("arff", ctx, nullptr, name);
  sink->write(scenes, out);
  sink->finish();
}

// "thesis,physics": each name a choice of the --model knob, none twice.
std::vector<Model> parse_models(const std::string& text) {
  const Knob* knob = find_knob("model");
  std::vector<Model> models;
  for (size_t start = 0;;) {
    const size_t comma = text.find(',', start);
    const std::string name = text.substr(start, comma == std::string::npos ? comma : comma - start);
    Plan p;
    set_knob(p, *knob, name, "--models");
    if (std::find(models.begin(), models.end(), p.model.model) != models.end())
      throw InputError("--models: \"" + name + "\" is listed twice");
    models.push_back(p.model.model);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return models;
}

// The thesis's experimental cases as scenarios/case1-gun.toml and case2-rod-plate.toml
// draw them: balanced, 0 to 4 objects; case 1 from every object, case 2 from its six.
SceneBatch thesis_case(const Catalogue& cat, int which, uint64_t seed, uint64_t count) {
  GeneratorSpec gs;
  gs.balance = true;
  if (which == 1) {
    gs.rule = "gun";
  } else {
    gs.rule = "iron-rod & metal-plate";
    for (const char* name :
         {"metal-plate", "iron-rod", "compact-disk", "cement-tile", "ceramic-plate", "mobile-phone"}) {
      const int o = cat.find_object(name);
      if (o < 0) throw InputError(std::string("thesis case 2 needs the catalogue object \"") + name + "\"");
      gs.pool.push_back(o);
    }
  }
  Generator gen(cat, gs, seed);
  SceneBatch batch(cat.region_count());
  for (uint64_t i = 0; i < count; ++i) batch.push(gen(i));
  return batch;
}

// The noise's distribution columns: the unit draws of the model's per-pixel noise (thesis:
// pixel noise; physics: the MMW raw noise, table Gaussians or the fast tier's draws) over up to 2,048 scenarios of
// 512 pixels, as the fp64 reference (no tier) or the tier's kernels make them.
constexpr size_t kDrawScenarios = 2048;
constexpr int kDrawCells = 512;

std::vector<double> reference_draws(Model m, uint64_t seed, size_t scenarios) {
  std::vector<double> v;
  v.reserve(scenarios * kDrawCells);
  for (uint64_t i = 0; i < scenarios; ++i)
    for (int p = 0; p < kDrawCells; ++p)
      v.push_back(m == Model::physics ? reference::table_gaussian(seed, i, kStreamRawNoise, 0, p)
                                      : reference::pixel_gaussian(seed, i, 0, p));
  return v;
}

void put_distribution(json& r, const std::vector<double>& draws) {
  const Distribution d = distribution(draws);
  double max_abs = 0;
  for (double g : draws) max_abs = std::max(max_abs, std::abs(g));
  r["noise_draws"] = draws.size();
  r["noise_mean"] = d.mean;
  r["noise_sd"] = d.sd;
  r["noise_skewness"] = d.skewness;
  r["noise_excess_kurtosis"] = d.excess_kurtosis;
  r["noise_ks"] = d.ks;
  r["noise_ks_critical"] = d.ks_critical;
  r["noise_max_abs"] = max_abs;
}

// One row's runs: the timed features-only and images runs of a tier (none: the reference)
// and their errors against the model's reference. img_feats, img_feats2: the features of the
// images runs of cases 1 and 2 where they are not the features-only run's (the block-mean
// noise model), for J48 on them.
struct RowRuns {
  std::string name;
  std::optional<Tier> tier;
  double feat_rate = 0, img_rate = 0;
  OutputDiff img_err, feat_err;
  const BatchOutput* feats = nullptr;
  BatchOutput feats2;
  const BatchOutput* img_feats = nullptr;
  const BatchOutput* img_feats2 = nullptr;
  const BatchOutput* img_out = nullptr;
};

// What one model's rows share: the options, both scenario sets, the staging folder of
// J48's ARFFs and the model's reference backend.
struct ModelRows {
  ModelRows(const TradeoffOptions& o, const Catalogue& cat, const SceneBatch& batch, const SceneBatch& case2,
            StagedFolder& folder, const ModelSettings& model, Backend& reference)
      : o(o), cat(cat), batch(batch), case2(case2), folder(folder), model(model), reference(reference) {}
  const TradeoffOptions& o;
  const Catalogue& cat;
  const SceneBatch& batch;
  const SceneBatch& case2;
  StagedFolder& folder;
  ModelSettings model;
  Backend& reference;
  std::string mname = model_name(model.model);
  // The reference following a tier's approximate pixel draws (Fidelity::draw), made once
  // per draw: the tier's images are held to it (the reference's Box-Muller draws are
  // other numbers, value by value).
  std::map<NoiseDraw, BatchOutput> same_draw_refs;

  const BatchOutput& same_draw_ref(NoiseDraw d) {
    auto it = same_draw_refs.find(d);
    if (it != same_draw_refs.end()) return it->second;
    Plan p = images_plan(model);
    p.fidelity.draw = d;
    reference.run(batch, p, same_draw_refs[d]);
    return same_draw_refs[d];
  }

  // J48's 10-fold accuracies, asked for as the rows are made and run at the model's end in
  // one JVM (cli/weka.h): row `row`'s column `key` is that of the ARFF `arff`.
  struct J48Column {
    size_t row;
    std::string key, arff;
  };
  std::vector<J48Column> j48_asked;

  // Writes one tier's features of one case as the ARFF `arff` for row `row`'s column `key`.
  void j48(size_t row, const std::string& key, const std::string& arff, const SceneBatch& scenes,
           const BatchOutput& feats) {
    write_arff(folder.dir(), arff, scenes, feats, cat);
    folder.path(arff);  // keep it
    j48_asked.push_back({row, key, arff});
  }

  // The model's J48 columns (or a note where WEKA cannot run), then its rows printed.
  void finish(json& rows, size_t first_row) {
    std::vector<WekaJob> jobs;
    std::map<std::string, size_t> job_of;  // an ARFF asked for twice is scored once
    for (const J48Column& c : j48_asked)
      if (job_of.emplace(c.arff, jobs.size()).second)
        jobs.push_back({.classifier = "j48",
                        .train = (std::filesystem::path(folder.dir()) / c.arff).string(),
                        .tests = {},
                        .folds = 10,
                        .seed = 1});
    std::string why;
    const auto scores = jobs.empty() ? std::vector<std::vector<WekaScore>>() : weka_scores(jobs, why);
    for (const J48Column& c : j48_asked) {
      if (scores)
        rows[c.row][c.key] = (*scores)[job_of[c.arff]][0].percent();
      else
        rows[c.row]["j48_note"] = why;
    }
    j48_asked.clear();
    for (size_t row = first_row; row < rows.size(); ++row) print_row(rows[row]);
  }

  // Case 2's features, one untimed pass (only the classifier reads them).
  BatchOutput case2_features(Backend& b, const Plan& plan) {
    BatchOutput out;
    if (o.classifier) b.run(case2, plan, out);
    return out;
  }

  // Fills the last row (which holds the noise's distribution columns already); finish()
  // prints it.
  void add_row(json& rows, const RowRuns& run) {
    json& r = rows.back();
    const Model m = model.model;
    r["model"] = mname;
    r["name"] = run.name;
    // What the noise's distribution columns sample (put_distribution).
    const bool irwin_hall = run.tier && tier_fidelity(*run.tier).draw == NoiseDraw::irwin_hall;
    r["noise_draw"] = irwin_hall ? "irwin-hall" : m == Model::physics ? "table Gaussian" : "box-muller";
    r["features_per_s"] = run.feat_rate;
    r["images_per_s"] = run.img_rate;
    r["mmw_max_abs"] = run.img_err.of(Camera::mmw).max_abs;
    r["mmw_rmse_mean"] = run.img_err.of(Camera::mmw).rmse_mean;
    r["mmw_rmse_max"] = run.img_err.of(Camera::mmw).rmse_max;
    r["mmw_psnr_db"] = run.img_err.of(Camera::mmw).psnr;
    r["mmw_share_off_by_more_than_1"] = run.img_err.of(Camera::mmw).share_off_by_more_than_1;
    r["mmw_share_differing"] = run.img_err.of(Camera::mmw).share_differing;
    r["ir_max_abs"] = run.img_err.of(Camera::ir).max_abs;
    r["ir_rmse_mean"] = run.img_err.of(Camera::ir).rmse_mean;
    r["ir_psnr_db"] = run.img_err.of(Camera::ir).psnr;
    r["ir_share_off_by_more_than_1"] = run.img_err.of(Camera::ir).share_off_by_more_than_1;
    r["feature_max_abs"] = run.feat_err.feature_max_abs;
    r["feature_mean_abs"] = run.feat_err.feature_mean_abs;
    r["metal_exact_rate"] = run.feat_err.metal_exact;
    r["label_exact_rate"] = 1.0;  // labels come from the scenes, which every tier shares
    std::string why;
    if (run.tier)
      why = tier_columns(r, *run.tier, run);
    else
      r["precision"] = "fp64 (CPU reference)";
    r["within_tolerance"] = why.empty();
    if (!why.empty()) r["tolerance_note"] = why;
    j48_columns(rows.size() - 1, r, run);
  }

  // A tier's fidelity columns and whether its runs are within the tier's stated tolerance for
  // this model (plan/tolerance.h), on images and features: empty, or what broke.
  std::string tier_columns(json& r, Tier tier, const RowRuns& run) {
    const Model m = model.model;
    const Fidelity f = tier_fidelity(tier);
    r["precision"] = precision_name(f.precision);
    r["pooling"] = f.pooling == Pooling::sparse ? "sparse" : "dense";
    r["fast_math"] = f.fast_math;
    r["noise_model"] = f.noise == NoiseModel::block_mean ? "block-mean" : "per-pixel";
    const Tolerance tol = model_tolerance(m, tier);
    // The features-only run holds no images. Its feature bounds hold without the
    // block-mean noise model, which draws each mean's noise directly (the thesis's
    // pixel noise; the physics model's NETD in feature space).
    OutputDiff feat_checked;
    feat_checked.metal_exact = run.feat_err.metal_exact;
    const bool noise_per_mean = model.pixel_sigma > 0 || (m == Model::physics && model.netd > 0);
    if (f.noise != NoiseModel::block_mean || !noise_per_mean) {
      feat_checked.feature_max_abs = run.feat_err.feature_max_abs;
      feat_checked.feature_mean_abs = run.feat_err.feature_mean_abs;
    }
    // A tier that draws the camera's frames as one approximate draw (Plan::frames_approximated)
    // has other noise than the reference's, value by value: its images are held to the
    // distribution instead (tests/camera_test.cpp); the error columns still show the cost.
    Plan tier_images = images_plan(model);
    tier_images.fidelity = f;
    // The thesis model has no camera frames (the frames knob is the physics camera's).
    const bool frames_approximated = m == Model::physics && tier_images.frames_approximated();
    r["frames_approximated"] = frames_approximated;
    // A tier with other pixel draws than the reference's is held to the reference
    // following them; its error columns stay against the model's reference.
    const bool other_draws = m == Model::thesis && model.pixel_sigma > 0 && f.draw != NoiseDraw::box_muller;
    r["images_held_to"] = other_draws ? "the reference with the tier's noise_draw" : "the model's reference";
    std::string why;
    if (!frames_approximated) {
      const OutputDiff held = other_draws ? compare_outputs(*run.img_out, same_draw_ref(f.draw)) : run.img_err;
      if (other_draws) {
        r["same_draw_mmw_max_abs"] = held.of(Camera::mmw).max_abs;
        r["same_draw_mmw_rmse_mean"] = held.of(Camera::mmw).rmse_mean;
        r["same_draw_mmw_share_differing"] = held.of(Camera::mmw).share_differing;
      }
      if (const std::string broke = check_tolerance(held, tol); !broke.empty()) why += "images run: " + broke;
    }
    if (const std::string broke = check_tolerance(feat_checked, tol); !broke.empty()) why += "features run: " + broke;
    return why;
  }

  void j48_columns(size_t row, json& r, const RowRuns& run) {
    r["j48_accuracy"] = nullptr;
    r["j48_case2_accuracy"] = nullptr;
    r["j48_images_accuracy"] = nullptr;
    r["j48_images_case2_accuracy"] = nullptr;
    if (!o.classifier) return;
    const std::string stem = mname + "-" + run.name;
    j48(row, "j48_accuracy", stem + "-case1.arff", batch, *run.feats);
    j48(row, "j48_case2_accuracy", stem + "-case2.arff", case2, run.feats2);
    // Features pooled from the images run: the features-only run's own where they are
    // the same numbers (the same ARFF), else J48 on them.
    if (run.img_feats) {
      j48(row, "j48_images_accuracy", stem + "-images-case1.arff", batch, *run.img_feats);
      j48(row, "j48_images_case2_accuracy", stem + "-images-case2.arff", case2, *run.img_feats2);
    } else {
      j48_asked.push_back({row, "j48_images_accuracy", stem + "-case1.arff"});
      j48_asked.push_back({row, "j48_images_case2_accuracy", stem + "-case2.arff"});
    }
  }

  static void print_row(const json& r) {
    auto pct = [&](const char* key) {
      char text[32] = "-";
      if (!r[key].is_null()) std::snprintf(text, sizeof text, "%.1f%%", r[key].get<double>());
      return std::string(text);
    };
    const std::string why = r.value("tolerance_note", "");
    std::printf(
        "  %-9s features %10.0f/s  images %8.0f/s  MMW max %d rmse %.4f  feature max %.4g  metal %.4f  noise sd %.4f "
        "kurtosis %+.3f KS %.4f  J48 case 1 %s case 2 %s (from images %s, %s)%s\n",
        r["name"].get<std::string>().c_str(), r["features_per_s"].get<double>(), r["images_per_s"].get<double>(),
        r["mmw_max_abs"].get<int>(), r["mmw_rmse_mean"].get<double>(), r["feature_max_abs"].get<double>(),
        r["metal_exact_rate"].get<double>(), r["noise_sd"].get<double>(), r["noise_excess_kurtosis"].get<double>(),
        r["noise_ks"].get<double>(), pct("j48_accuracy").c_str(), pct("j48_case2_accuracy").c_str(),
        pct("j48_images_accuracy").c_str(), pct("j48_images_case2_accuracy").c_str(),
        why.empty() ? "" : ("  OUT OF TOLERANCE: " + why).c_str());
    std::fflush(stdout);
  }
};

void print_model_header(const TradeoffOptions& o, const ModelSettings& model, const Catalogue& cat) {
  std::printf("tradeoff, %s model: %llu scenarios (case 1, balanced), pixel noise %.3g, block %d",
              model_name(model.model), static_cast<unsigned long long>(o.count), model.pixel_sigma, model.block);
  if (model.model == Model::physics) {
    std::printf(", NETD %.3g K, raw grid %dx%d, illumination %.4g K", model.netd, model.raw_width, model.raw_height,
                model.illumination);
    // The views whose camera keeps its own numbers over those (ModelSettings::for_view).
    for (const Sensor& v : cat.sensors) {
      if (v.netd) std::printf("; %s: NETD %.3g K", v.name.c_str(), *v.netd);
      if (v.raw) std::printf("; %s: raw grid %dx%d", v.name.c_str(), (*v.raw)[0], (*v.raw)[1]);
    }
  }
  std::printf("\n");
  std::fflush(stdout);
}

// The reference's row, then one row per tier, of one model.
void model_rows(ModelRows& mr, json& rows, const std::shared_ptr<OpenCLRuntime>& rt, const AssetSet& assets) {
  const TradeoffOptions& o = mr.o;
  const ModelSettings& model = mr.model;
  const Model m = model.model;
  const size_t draw_scenarios = std::min<size_t>(o.count, kDrawScenarios);
  const size_t first_row = rows.size();
  const Timed ref = run_timed(mr.reference, mr.batch, images_plan(model), 256, 0.0);
  const OutputDiff self = compare_outputs(ref.out, ref.out);
  // The reference renders every image for features too: one rate serves both, and its
  // features come from its images: the same numbers either way.
  put_distribution(rows.emplace_back(), reference_draws(m, model.seed, draw_scenarios));
  mr.add_row(rows, {.name = "reference",
                    .tier = std::nullopt,
                    .feat_rate = ref.rate,
                    .img_rate = ref.rate,
                    .img_err = self,
                    .feat_err = self,
                    .feats = &ref.out,
                    .feats2 = mr.case2_features(mr.reference, features_plan(model)),
                    .img_feats = nullptr,
                    .img_feats2 = nullptr,
                    .img_out = &ref.out});
  for (Tier t : {Tier::exact, Tier::standard, Tier::fast}) {
    const Fidelity f = tier_fidelity(t);
    auto cl = make_opencl_backend(mr.cat, assets, rt);
    Plan ip = images_plan(model), fp = features_plan(model);
    ip.fidelity = fp.fidelity = f;
    const Timed img = run_timed(*cl, mr.batch, ip, 1024, o.timed_seconds);
    const Timed feat = run_timed(*cl, mr.batch, fp, 16384, o.timed_seconds);
    put_distribution(rows.emplace_back(), opencl::noise_draws(*rt, f, opencl::KernelCounts::of(mr.cat), m, model.seed,
                                                              0, draw_scenarios, kDrawCells));
    const bool images_own_features = o.classifier && img.out.features != feat.out.features;
    BatchOutput img2;
    if (images_own_features) cl->run(mr.case2, ip, img2);
    mr.add_row(rows, {.name = tier_name(t),
                      .tier = t,
                      .feat_rate = feat.rate,
                      .img_rate = img.rate,
                      .img_err = compare_outputs(img.out, ref.out),
                      .feat_err = compare_outputs(feat.out, ref.out),
                      .feats = &feat.out,
                      .feats2 = mr.case2_features(*cl, fp),
                      .img_feats = images_own_features ? &img.out : nullptr,
                      .img_feats2 = images_own_features ? &img2 : nullptr,
                      .img_out = &img.out});
  }
  mr.finish(rows, first_row);
}

json tradeoff_report(const TradeoffOptions& o, const ModelSettings& base, const std::vector<Model>& models,
                     const Catalogue& cat, const OpenCLRuntime& rt, const json& rows) {
  json report;
  report["count"] = o.count;
  report["seed"] = std::to_string(base.seed);
  report["pixel_noise"] = base.pixel_sigma;
  report["pattern_noise"] = base.pattern_noise;
  report["block"] = base.block;
  report["timed_seconds"] = o.timed_seconds;
  report["models"] = json::array();
  for (Model m : models) report["models"].push_back(model_name(m));
  report["physics"] = {{"netd_k", base.netd},
                       {"mmw_raw", std::to_string(base.raw_width) + "x" + std::to_string(base.raw_height)},
                       {"illumination_k", base.illumination},
                       {"worn_minutes", base.worn_minutes}};
  for (const Sensor& v : cat.sensors) {  // a view's own camera, where it has one
    if (v.netd) report["physics"]["views"][v.name]["netd_k"] = *v.netd;
    if (v.raw)
      report["physics"]["views"][v.name]["mmw_raw"] = std::to_string((*v.raw)[0]) + "x" + std::to_string((*v.raw)[1]);
  }
  report["scenario_set"] = "thesis case 1: rule gun, balanced, 0..4 objects from every object";
  report["case2_scenario_set"] =
      "thesis case 2: rule iron-rod & metal-plate, balanced, 0..4 objects from metal-plate, iron-rod, compact-disk, "
      "cement-tile, ceramic-plate, mobile-phone (classifier only)";
  report["errors_against"] = "the fp64 CPU reference of the row's own model";
  report["machine"] = std::to_string(::sysconf(_SC_NPROCESSORS_ONLN)) + " cores, " + rt.device_name();
  report["rows"] = rows;
  return report;
}

std::string tradeoff_csv(const json& rows) {
  std::string csv =
      "model,tier,precision,features_per_s,images_per_s,mmw_max_abs,mmw_rmse_mean,mmw_psnr_db,"
      "mmw_share_off_by_more_than_1,ir_max_abs,feature_max_abs,feature_mean_abs,metal_exact_rate,label_exact_rate,"
      "j48_accuracy,j48_case2_accuracy,within_tolerance,noise_draw,noise_sd,noise_skewness,noise_excess_kurtosis,"
      "noise_ks,noise_max_abs,j48_images_accuracy,j48_images_case2_accuracy\n";
  auto opt = [](const json& v) { return v.is_null() ? std::string() : std::to_string(v.get<double>()); };
  for (const json& r : rows) {
    char line[768];
    std::snprintf(
        line, sizeof line,
        "%s,%s,%s,%.0f,%.0f,%d,%.6f,%.3f,%.8f,%d,%.6g,%.6g,%.6f,%.6f,%s,%s,%s,%s,%.6f,%.6f,%.6f,%.6f,%.4f,%s,"
        "%s\n",
        r["model"].get<std::string>().c_str(), r["name"].get<std::string>().c_str(),
        r["precision"].get<std::string>().c_str(), r["features_per_s"].get<double>(), r["images_per_s"].get<double>(),
        r["mmw_max_abs"].get<int>(), r["mmw_rmse_mean"].get<double>(), r["mmw_psnr_db"].get<double>(),
        r["mmw_share_off_by_more_than_1"].get<double>(), r["ir_max_abs"].get<int>(), r["feature_max_abs"].get<double>(),
        r["feature_mean_abs"].get<double>(), r["metal_exact_rate"].get<double>(), r["label_exact_rate"].get<double>(),
        opt(r["j48_accuracy"]).c_str(), opt(r["j48_case2_accuracy"]).c_str(),
        r["within_tolerance"].get<bool>() ? "yes" : "no", r["noise_draw"].get<std::string>().c_str(),
        r["noise_sd"].get<double>(), r["noise_skewness"].get<double>(), r["noise_excess_kurtosis"].get<double>(),
        r["noise_ks"].get<double>(), r["noise_max_abs"].get<double>(), opt(r["j48_images_accuracy"]).c_str(),
        opt(r["j48_images_case2_accuracy"]).c_str());
    csv += line;
  }
  return csv;
}

int tradeoff(TradeoffOptions& o) {
  if (o.count < 10 || o.count > 1000000) throw InputError("--count: must be between 10 and 1000000");
  if (o.out.empty()) throw InputError("--out: empty folder name");
  if (!(o.timed_seconds >= 0 && o.timed_seconds <= 60))  // NaN fails too
    throw InputError("--timed-seconds: must be a number of seconds between 0 and 60");
  const std::vector<Model> models = parse_models(o.models);
  Session s;
  open_catalogue(s, o.common);
  const Catalogue& cat = s.catalogue;
  ModelSettings base = o.model;
  base.seed = io::parse_u64(o.common.seed, "--seed");
  for (Model m : models) {
    Plan check = images_plan(base);
    check.model.model = m;
    validate(check, cat);
  }
  std::error_code ec;
  if (std::filesystem::exists(o.out, ec) && !std::filesystem::is_empty(o.out, ec))
    throw OutputError(o.out + ": is not empty; choose a new folder");
  // Case 2 is drawn first: it checks the catalogue before anything is written.
  const SceneBatch case2 = o.classifier ? thesis_case(cat, 2, base.seed, o.count) : SceneBatch(cat.region_count());
  const SceneBatch batch = thesis_case(cat, 1, base.seed, o.count);
  StagedFolder folder(o.out);

  auto rt = std::make_shared<OpenCLRuntime>(OpenCLOptions{o.common.device, ""});
  json rows = json::array();
  for (Model m : models) {
    ModelSettings model = base;
    model.model = m;
    print_model_header(o, model, cat);
    auto reference = make_reference_backend(cat, s.assets);
    ModelRows mr(o, cat, batch, case2, folder, model, *reference);
    model_rows(mr, rows, rt, s.assets);
  }
  write_text_atomic(folder.path("tradeoff.json"), tradeoff_report(o, base, models, cat, *rt, rows).dump(2) + "\n");
  write_text_atomic(folder.path("tradeoff.csv"), tradeoff_csv(rows));

  // The plot, drawn by the embedded matplotlib script; --no-plot for machines without it
  // (tools/device-check.sh on a GPU machine).
  if (o.plot) {
    const std::string staging = folder.dir();
    run_plot_script(embedded::plot_tradeoff, staging, {staging}, "tradeoff.png");
    folder.path("tradeoff.png");
  }
  folder.commit();
  std::printf("%s: tradeoff.json, tradeoff.csv%s%s\n", o.out.c_str(), o.plot ? ", tradeoff.png" : "",
              o.classifier ? ", two ARFFs (cases 1 and 2) per model and tier" : "");
  return 0;
}
}  // namespace

std::function<int()> add_tradeoff(CLI::App& app) {
  auto o = std::make_shared<TradeoffOptions>();
  o->model.pixel_sigma = 2.0;
  CLI::App* sub =
      app.add_subcommand("tradeoff", "measure every fidelity tier against the fp64 reference, per sensor model");
  sub->add_option("--count", o->count, "scenarios in the set (default 2000)");
  sub->add_option("--out", o->out, "output folder (default tradeoff)");
  sub->add_option("--seed", o->common.seed, "run seed (default 0)");
  sub->add_option("--catalogue", o->common.catalogue, "catalogue TOML file (default: the built-in one)");
  sub->add_option("--device", o->common.device, "OpenCL device: a substring of its platform or device name");
  sub->add_option("--pixel-noise", o->model.pixel_sigma, "per-pixel sensor noise sigma (default 2)");
  sub->add_option("--block", o->model.block, "feature block side (default 10)");
  sub->add_option("--models", o->models, "sensor models to measure, comma-separated (default thesis,physics)");
  sub->add_option(
      "--timed-seconds", o->timed_seconds,
      "each tier's three timed passes run at least this long (default 0.3; shorter: quicker, noisier rates)");
  sub->add_flag("!--no-classifier", o->classifier, "skip WEKA J48 (faster)");
  sub->add_flag("!--no-plot", o->plot, "skip tradeoff.png (needs no python3 with matplotlib)");
  return [o] { return tradeoff(*o); };
}

}  // namespace cli
}  // namespace portalsim
