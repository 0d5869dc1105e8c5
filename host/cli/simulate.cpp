// portalsim simulate: the thesis's command line (sections 4.2, 4.4) for one scenario.
#include <chrono>
#include <cstdio>

#include "base/error.h"
#include "cli/commands.h"
#include "cli/common.h"
#include "cli/python_requests.h"
#include "io/input_file.h"
#include "plan/knobs.h"
#include "serve/one_scenario.h"

namespace portalsim::cli {

namespace {
struct SimulateOptions {
  CommonOptions common;
  BodyOptions body;
  int subject = 1;
  std::string rule, threat, out = "portalsim-out", image_format = "png";
  std::vector<std::string> objects;
  std::string tier = "standard";
  bool stages = false;
  std::map<std::string, std::string> knobs;
  CLI::App* app = nullptr;
};

// The model and fidelity the flags ask for, checked against the catalogue.
Plan simulate_plan(const SimulateOptions& o, const Catalogue& cat) {
  Plan plan;
  plan.fidelity = tier_fidelity(parse_tier(o.tier, "--tier"));
  for (const auto& [key, text] : given_knobs(*o.app, o.knobs)) {
    const Knob& k = *find_knob(key);
    set_knob(plan, k, text, k.flag());
  }
  plan.model.seed = io::parse_u64(o.common.seed, "--seed");
  validate(plan, cat);
  return plan;
}

int simulate(SimulateOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  Session s;
  const RunSpec bodies = bodies_spec(o.body);
  open_catalogue(s, o.common, &bodies, given_knobs(*o.app, o.knobs).count("clothing_folds") > 0);
  const Catalogue& cat = s.catalogue;

  // Everything the user gave is checked before any backend work or any file is written.
  const Scenario scene = make_scenario(cat, ScenarioInputs{o.subject, o.objects, o.rule, o.threat});
  const Plan plan = simulate_plan(o, cat);

  open_backend(s, o.common);
  BatchOutput out;
  const StageFieldsRequest fields{cat, s.assets};
  const OneScenarioTimes t =
      write_one_scenario(o.out, cat, *s.backend, scene, plan, procedural::ir_palette(plan.palette),
                         FolderOptions{o.image_format}, out, o.stages ? &fields : nullptr);
  const double run_seconds = t.run_seconds, write_seconds = t.write_seconds;

  std::printf("%s: subject %d, threat %s, metal", o.out.c_str(), o.subject, scene.label ? "yes" : "no");
  for (int z = 0; z < cat.zones; ++z) std::printf("%s%d", z ? "," : " ", out.metal_of(0)[z]);
  std::printf("\n");
  if (o.common.timing) {
    const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("timing: catalogue %.4f s, assets %.4f s, backend setup %.4f s", s.catalogue_seconds, s.assets_seconds,
                s.backend_seconds);
    if (s.runtime)
      std::printf(" (kernel build %.4f s on %s)", s.runtime->build_seconds(), s.runtime->device_name().c_str());
    std::printf(", run %.4f s, write %.4f s, total %.4f s\n", run_seconds, write_seconds, total);
    print_paths(*s.backend, plan);
  }
  return 0;
}

void add_simulate_options(CLI::App* sub, SimulateOptions* o) {
  add_common_options(*sub, o->common);
  sub->add_option("objects", o->objects,
                  "objects for the catalogue's regions in order, 1..13 in the built-in one (none = empty region; gun:v "
                  "= vertical variant)");
  sub->add_option("--subject", o->subject,
                  "subject 1..5 (base images and base metal values), or a random body's number");
  add_body_options(*sub, o->body);
  sub->add_option("--rule", o->rule, "threat rule, e.g. gun or 'iron-rod&metal-plate'");
  sub->add_option("--threat", o->threat, "label the scenario yes or no")->check(CLI::IsMember({"yes", "no"}));
  sub->add_option("--out", o->out, "output folder (default portalsim-out)");
  sub->add_option("--image-format", o->image_format, "png or jpg")->check(CLI::IsMember({"png", "jpg"}));
  sub->add_flag("--stages", o->stages,
                "also write every stage's field of each view, as the reference computes it, to OUT/stages/"
                "<view>.<k>.<stage>.npy (float64)");
  add_knob_options(*sub, o->tier, o->knobs);
  o->app = sub;
}
}  // namespace

std::function<int()> add_simulate(CLI::App& app) {
  auto o = std::make_shared<SimulateOptions>();
  add_simulate_options(app.add_subcommand("simulate", "simulate the three sensors for one person carrying objects"),
                       o.get());
  return [o] { return simulate(*o); };
}

SimulateRequest parse_simulate(const std::vector<std::string>& args, const Catalogue* cat) {
  CLI::App app{"portalsim simulate"};
  SimulateOptions o;
  add_simulate_options(&app, &o);
  parse_args(app, args);
  SimulateRequest r;
  r.common = o.common;
  r.bodies = bodies_spec(o.body);
  if (cat) {
    r.scene = make_scenario(*cat, ScenarioInputs{o.subject, o.objects, o.rule, o.threat});
    r.plan = simulate_plan(o, *cat);
  }
  return r;
}

}  // namespace portalsim::cli
