// portalsim tradeoff: one scenario set through every fidelity tier and the fp64
// reference; throughput, error and the effect on a classifier, as JSON, CSV and a plot.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "backend/compare.h"
#include "backend/opencl/opencl_backend.h"
#include "base/error.h"
#include "cli/commands.h"
#include "cli/common.h"
#include "cli/weka.h"
#include "io/input_file.h"
#include "scene/generator.h"
#include "sink/sinks.h"
#include "sink/staging.h"

namespace portalsim {
namespace embedded {
extern const std::string_view plot_tradeoff;
}

namespace cli {

namespace {

using Clock = std::chrono::steady_clock;
using nlohmann::json;

struct TradeoffOptions {
  CommonOptions common;
  uint64_t count = 2000;
  std::string out = "tradeoff";
  ModelSettings model;
  bool classifier = true;
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
  SceneBatch s;
  s.first_index = b.first_index + first;
  s.subject.assign(b.subject.begin() + first, b.subject.begin() + first + n);
  s.objects.assign(b.objects.begin() + first * kRegions, b.objects.begin() + (first + n) * kRegions);
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

int tradeoff(TradeoffOptions& o) {
  if (o.count < 10 || o.count > 1000000) throw InputError("--count: must be between 10 and 1000000");
  if (o.out.empty()) throw InputError("--out: empty folder name");
  Session s;
  open_catalogue(s, o.common);
  const Catalogue& cat = s.catalogue;
  ModelSettings model = o.model;
  model.seed = io::parse_u64(o.common.seed, "--seed");
  Plan check = images_plan(model);
  validate(check, cat);
  std::error_code ec;
  if (std::filesystem::exists(o.out, ec) && !std::filesystem::is_empty(o.out, ec))
    throw OutputError(o.out + ": is not empty; choose a new folder");
  StagedFolder folder(o.out);

  // The scenario set: thesis case 1 (a gun is a threat), balanced, 0 to 4 objects.
  GeneratorSpec gs;
  gs.rule = "gun";
  gs.balance = true;
  Generator gen(cat, gs, model.seed);
  SceneBatch batch;
  for (uint64_t i = 0; i < o.count; ++i) batch.push(gen(i));

  auto rt = std::make_shared<OpenCLRuntime>(OpenCLOptions{o.common.device, ""});
  const std::string staging = folder.dir();

  std::printf("tradeoff: %llu scenarios (case 1, balanced), pixel noise %.3g, block %d\n",
              static_cast<unsigned long long>(o.count), model.pixel_sigma, model.block);
  std::fflush(stdout);
  auto reference = make_reference_backend(cat, s.assets);
  const Timed ref = run_timed(*reference, batch, images_plan(model), 256, 0.0);
  // The reference renders every image for features too: one rate serves both.
  json rows = json::array();
  auto add_row = [&](const std::string& name, const Fidelity* f, double feat_rate, double img_rate,
                     const OutputDiff& img_err, const OutputDiff& feat_err, const BatchOutput& feats) {
    json r;
    r["name"] = name;
    if (f) {
      r["precision"] = precision_name(f->precision);
      r["pooling"] = f->pooling == Pooling::sparse ? "sparse" : "dense";
      r["fast_math"] = f->fast_math;
      r["noise_model"] = f->noise == NoiseModel::block_mean ? "block-mean" : "per-pixel";
    } else {
      r["precision"] = "fp64 (CPU reference)";
    }
    r["features_per_s"] = feat_rate;
    r["images_per_s"] = img_rate;
    r["mmw_max_abs"] = img_err.mmw.max_abs;
    r["mmw_rmse_mean"] = img_err.mmw.rmse_mean;
    r["mmw_rmse_max"] = img_err.mmw.rmse_max;
    r["mmw_psnr_db"] = img_err.mmw.psnr;
    r["mmw_share_off_by_more_than_1"] = img_err.mmw.share_off_by_more_than_1;
    r["ir_max_abs"] = img_err.ir.max_abs;
    r["ir_rmse_mean"] = img_err.ir.rmse_mean;
    r["ir_psnr_db"] = img_err.ir.psnr;
    r["ir_share_off_by_more_than_1"] = img_err.ir.share_off_by_more_than_1;
    r["feature_max_abs"] = feat_err.feature_max_abs;
    r["feature_mean_abs"] = feat_err.feature_mean_abs;
    r["metal_exact_rate"] = feat_err.metal_exact;
    r["label_exact_rate"] = 1.0;  // labels come from the scenes, which every tier shares
    r["j48_accuracy"] = nullptr;
    if (o.classifier) {
      const std::string arff = name + ".arff";
      write_arff(staging, arff, batch, feats, cat);
      std::string why;
      if (auto acc = j48_cv_accuracy((std::filesystem::path(staging) / arff).string(), why))
        r["j48_accuracy"] = *acc;
      else
        r["j48_note"] = why;
      folder.path(arff);  // keep it
    }
    rows.push_back(r);
    std::printf(
        "  %-9s features %10.0f/s  images %8.0f/s  MMW max %d rmse %.4f  feature max %.4g  metal %.4f%s\n",
        name.c_str(), feat_rate, img_rate, img_err.mmw.max_abs, img_err.mmw.rmse_mean, feat_err.feature_max_abs,
        feat_err.metal_exact,
        r["j48_accuracy"].is_null() ? "" : ("  J48 " + std::to_string(r["j48_accuracy"].get<double>())).c_str());
    std::fflush(stdout);
  };
  const OutputDiff self = compare_outputs(ref.out, ref.out);
  add_row("reference", nullptr, ref.rate, ref.rate, self, self, ref.out);
  for (Tier t : {Tier::exact, Tier::standard, Tier::fast}) {
    const Fidelity f = tier_fidelity(t);
    auto cl = make_opencl_backend(cat, s.assets, rt);
    Plan ip = images_plan(model), fp = features_plan(model);
    ip.fidelity = fp.fidelity = f;
    const Timed img = run_timed(*cl, batch, ip, 1024, 0.3);
    const Timed feat = run_timed(*cl, batch, fp, 16384, 0.3);
    add_row(tier_name(t), &f, feat.rate, img.rate, compare_outputs(img.out, ref.out),
            compare_outputs(feat.out, ref.out), feat.out);
  }

  json report;
  report["count"] = o.count;
  report["seed"] = std::to_string(model.seed);
  report["pixel_noise"] = model.pixel_sigma;
  report["pattern_noise"] = model.pattern_noise;
  report["block"] = model.block;
  report["scenario_set"] = "thesis case 1: rule gun, balanced, 0..4 objects from every object";
  report["machine"] = std::to_string(::sysconf(_SC_NPROCESSORS_ONLN)) + " cores, " + rt->device_name();
  report["rows"] = rows;
  write_text_atomic(folder.path("tradeoff.json"), report.dump(2) + "\n");
  std::string csv =
      "tier,precision,features_per_s,images_per_s,mmw_max_abs,mmw_rmse_mean,mmw_psnr_db,mmw_share_off_by_more_than_1,"
      "ir_max_abs,feature_max_abs,feature_mean_abs,metal_exact_rate,label_exact_rate,j48_accuracy\n";
  for (const json& r : rows) {
    char line[512];
    std::snprintf(line, sizeof line, "%s,%s,%.0f,%.0f,%d,%.6f,%.3f,%.8f,%d,%.6g,%.6g,%.6f,%.6f,%s\n",
                  r["name"].get<std::string>().c_str(), r["precision"].get<std::string>().c_str(),
                  r["features_per_s"].get<double>(), r["images_per_s"].get<double>(), r["mmw_max_abs"].get<int>(),
                  r["mmw_rmse_mean"].get<double>(), r["mmw_psnr_db"].get<double>(),
                  r["mmw_share_off_by_more_than_1"].get<double>(), r["ir_max_abs"].get<int>(),
                  r["feature_max_abs"].get<double>(), r["feature_mean_abs"].get<double>(),
                  r["metal_exact_rate"].get<double>(), r["label_exact_rate"].get<double>(),
                  r["j48_accuracy"].is_null() ? "" : std::to_string(r["j48_accuracy"].get<double>()).c_str());
    csv += line;
  }
  write_text_atomic(folder.path("tradeoff.csv"), csv);

  // The plot, drawn by the embedded matplotlib script.
  const std::string script = (std::filesystem::path(staging) / ".plot_tradeoff.py").string();
  write_text_atomic(script, std::string(embedded::plot_tradeoff));
  // Debian's matplotlib belongs to the system interpreter, which may not be first on PATH.
  const std::string python = std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  const std::string cmd = python + " '" + script + "' '" + staging + "'";
  const int rc = std::system(cmd.c_str());
  std::filesystem::remove(script, ec);
  if (rc != 0) throw OutputError("tradeoff.png: the plot failed (python3 with matplotlib is needed)");
  folder.path("tradeoff.png");
  folder.commit();
  std::printf("%s: tradeoff.json, tradeoff.csv, tradeoff.png%s\n", o.out.c_str(),
              o.classifier ? ", one ARFF per tier" : "");
  return 0;
}
}  // namespace

std::function<int()> add_tradeoff(CLI::App& app) {
  auto o = std::make_shared<TradeoffOptions>();
  o->model.pixel_sigma = 2.0;
  CLI::App* sub = app.add_subcommand("tradeoff", "measure every fidelity tier against the fp64 reference");
  sub->add_option("--count", o->count, "scenarios in the set (default 2000)");
  sub->add_option("--out", o->out, "output folder (default tradeoff)");
  sub->add_option("--seed", o->common.seed, "run seed (default 0)");
  sub->add_option("--catalogue", o->common.catalogue, "catalogue TOML file (default: the built-in one)");
  sub->add_option("--device", o->common.device, "OpenCL device: a substring of its platform or device name");
  sub->add_option("--pixel-noise", o->model.pixel_sigma, "per-pixel sensor noise sigma (default 2)");
  sub->add_option("--block", o->model.block, "feature block side (default 10)");
  sub->add_flag("!--no-classifier", o->classifier, "skip WEKA J48 (faster)");
  return [o] { return tradeoff(*o); };
}

}  // namespace cli
}  // namespace portalsim
