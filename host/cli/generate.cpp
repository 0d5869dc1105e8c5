// portalsim generate: labelled data sets in bulk (thesis chapter 6 at scale).
#include <unistd.h>

#include <csignal>
#include <cstdio>

#include "base/error.h"
#include "cli/commands.h"
#include "cli/common.h"
#include "cli/python_requests.h"
#include "io/input_file.h"
#include "schedule/pipeline.h"
#include "schedule/ranked_run.h"
#include "schedule/scenario_source.h"

namespace portalsim::cli {

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop = true; }

struct GenerateOptions {
  CommonOptions common;
  RunSpec spec;
  std::string count, out, spec_file, objects, pool, subjects, formats, shard, png_level;
  std::map<std::string, std::string> knobs;
  long long batch = 0;
  unsigned threads = 0;
  bool resume = false, quiet = false;
  CLI::App* app = nullptr;
};

// The run the flags ask for: the --spec file, then the flags given over it.
RunSpec build_spec(GenerateOptions& o) {
  CLI::App& app = *o.app;
  RunSpec spec;
  if (!o.spec_file.empty()) read_spec_file(o.spec_file, spec);
  // Flags given on the command line override the spec file.
  const auto given = [&](const char* name) {
    const bool g = app.get_option(name)->count() > 0;
    if (g) {  // the flag overrides the spec file: errors name the flag
      std::string key = std::string(name).substr(2);
      for (char& c : key)
        if (c == '-') c = '_';
      spec.origin.erase(key);
    }
    return g;
  };
  if (given("--count")) {
    spec.count = io::parse_u64(o.count, "--count");
    if (spec.count < 1 || spec.count > (1ull << 40))
      throw InputError("--count: \"" + o.count + "\" is not between 1 and 2^40");
  }
  if (given("--seed")) spec.seed = io::parse_u64(o.common.seed, "--seed");
  if (given("--rule")) spec.rule = o.spec.rule;
  if (given("--pool")) {
    spec.pool = split_list(o.pool);
    if (spec.pool.empty()) throw InputError("--pool: no object names given");
  }
  if (given("--objects")) parse_object_range(o.objects, "--objects", spec);
  if (given("--subjects")) {
    spec.subjects.clear();
    for (const std::string& s : split_list(o.subjects)) {
      if (s.empty() || s.size() > 3 || s.find_first_not_of("0123456789") != std::string::npos)
        throw InputError("--subjects: \"" + s + "\" is not a subject number");
      spec.subjects.push_back(std::stoi(s));
    }
  }
  if (given("--balance")) spec.balance = o.spec.balance;
  if (given("--what")) spec.what = o.spec.what;
  if (given("--format")) spec.formats = split_list(o.formats);
  if (given("--image-format")) spec.image_format = o.spec.image_format;
  if (given("--png-level")) {
    const uint64_t level = io::parse_u64(o.png_level, "--png-level");
    if (level > kMaxPngLevel)
      throw InputError("--png-level: \"" + o.png_level + "\" is not between 0 and " + std::to_string(kMaxPngLevel));
    spec.png_level = static_cast<int>(level);
  }
  if (given("--compress")) spec.compress = o.spec.compress;
  if (given("--annotations")) spec.annotations = o.spec.annotations;
  if (given("--scenarios")) spec.scenarios = o.spec.scenarios;
  if (given("--tier")) spec.tier = o.spec.tier;
  for (const auto& [key, text] : given_knobs(app, o.knobs)) {
    spec.origin.erase(key);
    spec.set_knob_text(key, text, spec.where(key));
  }
  spec.validate();
  return spec;
}

int generate(GenerateOptions& o) {
  CLI::App& app = *o.app;
  // Under an MPI launcher every rank runs this; rank 0 alone speaks.
  std::unique_ptr<Ranks> alone;
  Ranks* ranks = mpi_ranks();
  if (!ranks) ranks = (alone = single_rank()).get();
  if (ranks->rank() != 0) print_errors(false);
  const RunSpec spec = build_spec(o);
  if (o.out.empty()) throw InputError("--out: empty folder name");

  PipelineOptions popt;
  popt.batch = static_cast<size_t>(std::max(0ll, o.batch));
  popt.threads = o.threads;
  popt.resume = o.resume;
  const bool ranked = ranks->size() > 1 || has_ranked_parts(o.out);
  popt.progress = !o.quiet && (::isatty(STDERR_FILENO) || (ranked && ranks->size() > 1));
  popt.stop = &g_stop;
  if (!o.shard.empty()) {
    const size_t slash = o.shard.find('/');
    if (slash == std::string::npos) throw InputError("--shard: \"" + o.shard + "\" is not i/k");
    popt.shard = io::parse_u64(o.shard.substr(0, slash), "--shard");
    popt.shards = io::parse_u64(o.shard.substr(slash + 1), "--shard");
    if (popt.shards < 1 || popt.shard >= popt.shards) throw InputError("--shard: \"" + o.shard + "\" needs 0 <= i < k");
  }
  if (app.get_option("--batch")->count() > 0 && (o.batch < 1 || o.batch > 1000000))
    throw InputError("--batch: " + std::to_string(o.batch) + " is not between 1 and 1000000");

  Session s;
  // Together: a rank that cannot start stops them all, rather than leaving them waiting.
  ranks->together([&] {
    open_catalogue(s, o.common);
    check_generate(spec, s.catalogue);
    open_backend(s, o.common);
  });

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  const PipelineResult r = ranked ? run_ranked(spec, s.catalogue, s.assets, *s.backend, o.out, popt, *ranks)
                                  : run_pipeline(spec, s.catalogue, s.assets, *s.backend, o.out, popt);
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  if (ranks->rank() != 0) return r.interrupted ? 130 : 0;

  if (r.already_complete) {
    std::printf("%s: already complete (manifest.json present); nothing to do\n", o.out.c_str());
    return 0;
  }
  const double rate = r.seconds > 0 ? r.done / r.seconds : 0;
  // An interrupted run's summary says so first, and how to finish it: it must not read as a
  // finished run's.
  const std::string range = "[" + std::to_string(r.begin) + ", " + std::to_string(r.end) + ")";
  const std::string what = r.interrupted ? "interrupted after " + std::to_string(r.done) + " scenarios of " + range
                                         : std::to_string(r.done) + " scenarios " + range;
  std::printf("%s: %s in %.2f s, %.0f scenarios/s (%s backend, batch %zu%s); positive %llu, negative %llu%s\n",
              o.out.c_str(), what.c_str(), r.seconds, rate, s.backend->name().c_str(), r.batch,
              ranked ? (", " + std::to_string(ranks->size()) + (ranks->size() == 1 ? " rank" : " ranks")).c_str() : "",
              static_cast<unsigned long long>(r.positive), static_cast<unsigned long long>(r.negative),
              r.interrupted ? " so far; not finished: run the same command with --resume to finish it" : "");
  if (o.common.timing)
    std::printf("timing: compute %.3f s (%.0f scenarios/s), waiting for the writer %.3f s%s\n", r.compute_seconds,
                r.compute_seconds > 0 ? r.done / r.compute_seconds : 0.0, r.write_wait_seconds,
                s.runtime ? (", kernel build " + std::to_string(s.runtime->build_seconds()) + " s").c_str() : "");
  if (o.common.timing) print_paths(*s.backend, run_plan(spec, s.catalogue));
  if (r.interrupted) {
    std::fprintf(stderr, "portalsim: interrupted; %s is consistent, run the same command with --resume to finish it\n",
                 o.out.c_str());
    return 130;
  }
  return 0;
}

void add_generate_options(CLI::App* sub, GenerateOptions* o) {
  o->app = sub;
  add_common_options(*sub, o->common);
  sub->add_option("--spec", o->spec_file, "TOML spec file; command-line flags override its keys");
  sub->add_option("--count", o->count, "number of scenarios (default 1000)");
  sub->add_option("--out", o->out, "output folder (must be new or empty, unless --resume)")->required();
  sub->add_option("--rule", o->spec.rule, "threat rule, e.g. gun or 'iron-rod&metal-plate'");
  sub->add_option("--pool", o->pool, "objects to draw from, comma-separated (default: all)");
  sub->add_option("--objects", o->objects, "objects per scenario, MIN..MAX (default 0..4)");
  sub->add_option("--subjects", o->subjects, "subjects to draw from, e.g. 1,2,5 (default: all)");
  sub->add_flag("--balance", o->spec.balance, "equal classes: even indices threats, odd not");
  sub->add_option("--what", o->spec.what, "features, images or both (default features)");
  sub->add_option("--format", o->formats,
                  "arff,csv,npy feature tables; h5: data.h5 with image tensors and labels; npy with --what images: "
                  "image tensors as .npy (default arff)");
  sub->add_flag("--compress", o->spec.compress, "gzip data.h5's datasets (--format h5)");
  sub->add_flag("--annotations", o->spec.annotations,
                "per-object boxes and instance masks: annotations.json (COCO), YOLO .txt and mask images");
  sub->add_option("--image-format", o->spec.image_format, "png or jpg (default png)");
  sub->add_option("--png-level", o->png_level,
                  "image folders' PNG compression, 0 (none) to 9 (smallest); default 1, the fastest that compresses");
  sub->add_option("--scenarios", o->spec.scenarios, "explicit scenario list (CSV: subject, region1..13, label)");
  add_knob_options(*sub, o->spec.tier, o->knobs);
  sub->add_option("--batch", o->batch, "scenarios per kernel launch (default: about 16 MiB of outputs)");
  sub->add_option("--threads", o->threads, "host threads for generating and writing (default: all cores)");
  sub->add_option("--shard", o->shard, "i/k: make only part i (0-based) of k of the index range");
  sub->add_flag("--resume", o->resume, "continue an interrupted run in --out");
  sub->add_flag("--quiet", o->quiet, "no progress bar");
}

}  // namespace

std::function<int()> add_generate(CLI::App& app) {
  auto o = std::make_shared<GenerateOptions>();
  add_generate_options(app.add_subcommand("generate", "make a labelled data set of many scenarios"), o.get());
  return [o] { return generate(*o); };
}

void check_generate(const RunSpec& spec, const Catalogue& cat) {
  // The generator's spec, before any output exists.
  if (spec.scenarios.empty()) Generator check(cat, generator_spec(spec, cat), spec.seed);
  validate(spec.settings(), cat);
}

GenerateRequest parse_generate(const std::vector<std::string>& args) {
  CLI::App app{"portalsim generate"};
  GenerateOptions o;
  add_generate_options(&app, &o);
  parse_args(app, args);
  GenerateRequest r;
  r.spec = build_spec(o);
  r.common = o.common;
  r.threads = o.threads;
  return r;
}

}  // namespace portalsim::cli
