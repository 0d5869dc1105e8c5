#include "cli/spec_flags.h"

#include "base/error.h"
#include "io/input_file.h"
#include "schedule/scenario_source.h"
#include "sink/sink_kinds.h"

namespace portalsim::cli {

void add_spec_flags(CLI::App* sub, SpecFlags* o, bool outputs) {
  o->app = sub;
  add_common_options(*sub, o->common);
  sub->add_option("--spec", o->spec_file, "TOML spec file; command-line flags override its keys");
  sub->add_option("--count", o->count, "number of scenarios (default 1000)");
  sub->add_option("--rule", o->spec.rule, "threat rule, e.g. gun or 'iron-rod&metal-plate'");
  sub->add_option("--pool", o->pool,
                  "objects to draw from, comma-separated: names, class:NAME, family:NAME or all (default: the "
                  "catalogue's default_pool)");
  sub->add_option("--objects", o->objects, "objects per scenario, MIN..MAX (default 0..4)");
  sub->add_option("--subjects", o->subjects, "subjects to draw from, e.g. 1,2,5 (default: all)");
  add_body_options(*sub, o->body, "--seed; give it apart to keep the bodies over other scenarios");
  sub->add_flag("--balance", o->spec.balance, "equal classes: even indices threats, odd not");
  if (outputs) {
    sub->add_option("--what", o->spec.what, "features, images or both (default features)");
    sub->add_option("--format", o->formats, format_help());
    sub->add_flag("--compress", o->spec.compress, "gzip data.h5's datasets (--format h5)");
    sub->add_flag("--annotations", o->spec.annotations,
                  "per-object boxes and instance masks: annotations.json (COCO), YOLO .txt and mask images");
    sub->add_option("--image-format", o->spec.image_format, "png or jpg (default png)");
    sub->add_option("--png-level", o->png_level,
                    "image folders' PNG compression, 0 (none) to 9 (smallest); default 1, the fastest that compresses");
    sub->add_option("--scenarios", o->spec.scenarios, "explicit scenario list (CSV: subject, region1..regionR, label)");
  }
  add_knob_options(*sub, o->spec.tier, o->knobs);
}

RunSpec build_spec(SpecFlags& o) {
  CLI::App& app = *o.app;
  RunSpec spec;
  if (!o.spec_file.empty()) read_spec_file(o.spec_file, spec);
  // Flags given on the command line override the spec file.
  const auto given = [&](const char* name) {
    const CLI::Option* option = app.get_option_no_throw(name);
    const bool g = option && option->count() > 0;
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
  if (given("--bodies")) spec.bodies = o.body.bodies;
  if (given("--body-seed")) spec.body_seed = io::parse_u64(o.body.seed, "--body-seed");
  if (given("--body-count")) spec.body_count = parse_body_count(o.body.count);
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
  check_formats(spec);
  return spec;
}

}  // namespace portalsim::cli
