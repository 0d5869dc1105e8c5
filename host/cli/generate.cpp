// portalsim generate: labelled data sets in bulk (thesis chapter 6 at scale).
#include <unistd.h>

#include <csignal>
#include <cstdio>

#include "base/error.h"
#include "cli/commands.h"
#include "cli/common.h"
#include "cli/python_requests.h"
#include "cli/spec_flags.h"
#include "io/input_file.h"
#include "schedule/pipeline.h"
#include "schedule/ranked_run.h"
#include "schedule/scenario_source.h"

namespace portalsim::cli {

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop = true; }

struct GenerateOptions {
  SpecFlags flags;
  std::string out, shard;
  long long batch = 0;
  unsigned threads = 0;
  bool resume = false, quiet = false;
};

int generate(GenerateOptions& o) {
  CLI::App& app = *o.flags.app;
  const CommonOptions& common = o.flags.common;
  // Under an MPI launcher every rank runs this; rank 0 alone speaks.
  std::unique_ptr<Ranks> alone;
  Ranks* ranks = mpi_ranks();
  if (!ranks) ranks = (alone = single_rank()).get();
  if (ranks->rank() != 0) print_errors(false);
  const RunSpec spec = build_spec(o.flags);
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
    open_catalogue(s, common, &spec, spec.settings().model.has_folds());
    check_generate(spec, s.catalogue);
    open_backend(s, common);
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
  if (common.timing)
    std::printf("timing: compute %.3f s (%.0f scenarios/s), waiting for the writer %.3f s%s\n", r.compute_seconds,
                r.compute_seconds > 0 ? r.done / r.compute_seconds : 0.0, r.write_wait_seconds,
                s.runtime ? (", kernel build " + std::to_string(s.runtime->build_seconds()) + " s").c_str() : "");
  if (common.timing) print_paths(*s.backend, run_plan(spec, s.catalogue));
  if (r.interrupted) {
    std::fprintf(stderr, "portalsim: interrupted; %s is consistent, run the same command with --resume to finish it\n",
                 o.out.c_str());
    return 130;
  }
  return 0;
}

void add_generate_options(CLI::App* sub, GenerateOptions* o) {
  add_spec_flags(sub, &o->flags, true);
  sub->add_option("--out", o->out, "output folder (must be new or empty, unless --resume)")->required();
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
  r.spec = build_spec(o.flags);
  r.common = o.flags.common;
  r.threads = o.threads;
  return r;
}

}  // namespace portalsim::cli
