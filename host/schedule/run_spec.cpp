#include "schedule/run_spec.h"

#include <cmath>
#include <filesystem>

#include "base/error.h"
#include "io/input_file.h"
#include "io/toml_input.h"
#include "plan/knobs.h"

namespace portalsim {

nlohmann::json RunSpec::to_json() const {
  nlohmann::json j;
  j["count"] = count;
  j["seed"] = std::to_string(seed);
  j["pool"] = pool;
  j["objects"] = {min_objects, max_objects};
  j["subjects"] = subjects;
  if (random_bodies()) {  // absent for the catalogue's subjects: older runs keep their identity
    j["bodies"] = bodies;
    j["body_count"] = random_bodies();
    j["body_seed"] = std::to_string(bodies_seed());
  } else if (per_scenario_bodies()) {
    j["bodies"] = bodies;
    j["body_seed"] = std::to_string(bodies_seed());
  }
  j["rule"] = rule;
  j["balance"] = balance;
  j["scenarios"] = scenarios;
  j["what"] = what;
  j["format"] = formats;
  j["image_format"] = image_format;
  j["compress"] = compress;
  if (annotations) j["annotations"] = true;  // absent when off: older runs keep their identity
  // The PNGs' bytes depend on the level (their pixels do not): a resume or a shard at
  // another level would leave a folder whose files differ from one run's.
  if (image_folders()) j["png_level"] = png_level;
  // The fidelity changes the numbers (within its tier's tolerance), so it is part of
  // the identity; knobs that never change a bit (pooling) are not.
  const Plan p = settings();
  j["tier"] = tier;
  // noise_draw is absent at Box-Muller, as before it existed: standard and exact runs keep
  // their identity and bytes; the fast tier's (Irwin-Hall) names it.
  for (const Knob& k : portalsim::knobs())
    if (k.identity && !(k.key == "noise_draw" && p.fidelity.draw == NoiseDraw::box_muller)) {
      nlohmann::json v = k.get(p);
      if (!(k.omit_default && knob_text(v) == k.def)) j[k.key] = std::move(v);
    }
  return j;
}

Plan RunSpec::settings() const {
  Plan p;
  p.fidelity = tier_fidelity(parse_tier(tier, where("tier")));
  for (const auto& [key, text] : knobs) set_knob(p, *find_knob(key), text, where(key));
  p.model.seed = seed;
  return p;
}

void RunSpec::set_knob_text(const std::string& key, const std::string& text, const std::string& at) {
  Plan scratch;
  set_knob(scratch, *find_knob(key), text, at);
  knobs[key] = text;
}

void RunSpec::validate() const {
  if (scenarios.empty() && (count < 1 || count > (1ull << 40)))
    throw InputError(where("count") + ": " + std::to_string(count) + " is not between 1 and 2^40");
  if (what != "features" && what != "images" && what != "both")
    throw InputError(where("what") + ": \"" + what + "\" is not features, images or both");
  if (wants_features() && formats.empty()) throw InputError(where("format") + ": give at least one of arff, csv, npy");
  // Each value's meaning is its sink kind's (check_formats, scenario_source.h).
  for (size_t i = 0; i < formats.size(); ++i) {
    for (size_t j = 0; j < i; ++j)
      if (formats[j] == formats[i]) throw InputError(where("format") + ": \"" + formats[i] + "\" given twice");
  }
  if (compress && !has_format("h5")) throw InputError(where("compress") + ": only applies to --format h5");
  if (annotations && !wants_images()) throw InputError(where("annotations") + ": needs images (--what images or both)");
  if (image_format != "png" && image_format != "jpg")
    throw InputError(where("image_format") + ": \"" + image_format + "\" is not png or jpg");
  if (png_level < 0 || png_level > kMaxPngLevel)
    throw InputError(where("png_level") + ": " + std::to_string(png_level) + " is not between 0 and " +
                     std::to_string(kMaxPngLevel));
  if (png_level != kDefaultPngLevel && !image_folders())
    throw InputError(where("png_level") +
                     ": only applies to image folders (--what images or both, without h5 or npy "
                     "image tensors)");
  if (balance && rule.empty()) throw InputError(where("balance") + ": needs a threat rule (--rule)");
  if (bodies != "catalogue" && bodies != "random" && bodies != "per-scenario")
    throw InputError(where("bodies") + ": \"" + bodies + "\" is not catalogue, random or per-scenario");
  if (body_seed && !drawn_bodies())
    throw InputError(where("body_seed") + ": only applies to drawn bodies (--bodies random or per-scenario)");
  if (body_count != 0 && bodies != "random")
    throw InputError(where("body_count") + ": only applies to random bodies (--bodies random)");
  if (body_count < 0 || body_count > kMaxRandomBodies)
    throw InputError(where("body_count") + ": " + std::to_string(body_count) + " is not between 1 and " +
                     std::to_string(kMaxRandomBodies));
  // A scenario's subject is its own body: none to choose, and a list's subject column names
  // one of a catalogue's.
  if (per_scenario_bodies() && !subjects.empty())
    throw InputError(where("subjects") + ": does not apply to per-scenario bodies (each scenario has its own)");
  if (per_scenario_bodies() && !scenarios.empty())
    throw InputError(
        where("scenarios") +
        ": a scenario list names its subjects, which per-scenario bodies do not have; use --bodies random");
  (void)settings();  // checks the tier and knobs
}

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : text + ",")
    if (c == ',') {
      if (!cur.empty()) out.push_back(cur);
      cur.clear();
    } else if (c != ' ') {
      cur.push_back(c);
    }
  return out;
}

void parse_object_range(const std::string& text, const std::string& where, RunSpec& spec) {
  const auto number = [&](const std::string& s) {
    if (s.empty() || s.size() > 2 || s.find_first_not_of("0123456789") != std::string::npos)
      throw InputError(where + ": \"" + text + "\" is not MIN..MAX with 0 <= MIN <= MAX <= 13");
    return std::stoi(s);
  };
  const size_t dots = text.find("..");
  const int lo = number(dots == std::string::npos ? text : text.substr(0, dots));
  const int hi = dots == std::string::npos ? lo : number(text.substr(dots + 2));
  if (lo > hi || hi > 13) throw InputError(where + ": \"" + text + "\" is not MIN..MAX with 0 <= MIN <= MAX <= 13");
  spec.min_objects = lo;
  spec.max_objects = hi;
}

namespace {

// A TOML value as the knob's text ("10", "2.5", "on", "bilinear"); the type is checked here,
// the value by set_knob.
std::string knob_value(const Knob& k, const toml::node& n, const std::string& at) {
  if (k.drawn >= 0 && n.is_string()) return n.as_string()->get();  // "A..B", drawn per scenario
  switch (k.kind) {
    case KnobKind::integer:
      if (!n.is_integer())
        throw InputError(at + (k.drawn >= 0 ? ": expected an integer or a string \"A..B\"" : ": expected an integer"));
      return std::to_string(n.as_integer()->get());
    case KnobKind::number:
      if (n.is_integer()) return std::to_string(n.as_integer()->get());
      if (!n.is_floating_point()) throw InputError(at + ": expected a number");
      return knob_text(n.as_floating_point()->get());
    case KnobKind::on_off:
      if (!n.is_boolean()) throw InputError(at + ": expected true or false");
      return n.as_boolean()->get() ? "on" : "off";
    case KnobKind::range:  // 30 or "-10..20"
      if (n.is_integer()) return std::to_string(n.as_integer()->get());
      if (n.is_floating_point()) return knob_text(n.as_floating_point()->get());
      if (!n.is_string()) throw InputError(at + ": expected a number or a string (" + k.values() + ")");
      return n.as_string()->get();
    case KnobKind::grid:
    case KnobKind::choice:
      if (!n.is_string()) throw InputError(at + ": expected a string (" + k.values() + ")");
      return n.as_string()->get();
  }
  return "";
}

}  // namespace

void read_spec_file(const std::string& path, RunSpec& spec) {
  parse_spec(io::read_file(path, "spec file", io::kMaxTextBytes), path, spec);
}

void parse_spec(std::string_view text, const std::string& path, RunSpec& spec) {
  const toml::table t = io::parse_toml(text, path);
  const auto at = [&](const toml::node& n, const std::string& key) {
    return path + ":" + std::to_string(n.source().begin.line) + ": " + key;
  };
  const auto integer = [&](const toml::node& n, const std::string& key, long long lo, long long hi) {
    if (!n.is_integer()) throw InputError(at(n, key) + ": expected an integer");
    const long long v = n.as_integer()->get();
    if (v < lo || v > hi)
      throw InputError(at(n, key) + ": " + std::to_string(v) + " is out of range [" + std::to_string(lo) + ", " +
                       std::to_string(hi) + "]");
    return v;
  };
  const auto string = [&](const toml::node& n, const std::string& key) {
    if (!n.is_string()) throw InputError(at(n, key) + ": expected a string");
    return n.as_string()->get();
  };
  const auto strings = [&](const toml::node& n, const std::string& key) {
    std::vector<std::string> out;
    if (n.is_string()) return split_list(n.as_string()->get());
    const toml::array* a = n.as_array();
    if (!a) throw InputError(at(n, key) + ": expected an array of strings");
    for (const toml::node& e : *a) out.push_back(string(e, key));
    return out;
  };
  const auto boolean = [&](const toml::node& n, const std::string& key) {
    if (!n.is_boolean()) throw InputError(at(n, key) + ": expected true or false");
    return n.as_boolean()->get();
  };
  const std::string dir = std::filesystem::absolute(path).parent_path().string();
  for (const auto& [k, node] : t) {
    const std::string key(k.str());
    spec.origin[key] = at(node, key);
    if (key == "count") {
      spec.count = static_cast<uint64_t>(integer(node, key, 1, 1ll << 40));
    } else if (key == "seed") {
      if (node.is_integer())
        spec.seed = static_cast<uint64_t>(integer(node, key, 0, INT64_MAX));
      else
        throw InputError(at(node, key) + ": expected a non-negative integer (use --seed for values above 2^63)");
    } else if (key == "rule") {
      spec.rule = string(node, key);
    } else if (key == "pool") {
      spec.pool = strings(node, key);
    } else if (key == "objects") {
      if (node.is_string()) {
        parse_object_range(string(node, key), at(node, key), spec);
      } else if (const toml::array* a = node.as_array(); a && a->size() == 2) {
        spec.min_objects = static_cast<int>(integer(*a->get(0), key, 0, 13));
        spec.max_objects = static_cast<int>(integer(*a->get(1), key, 0, 13));
        if (spec.min_objects > spec.max_objects) throw InputError(at(node, key) + ": MIN is above MAX");
      } else {
        throw InputError(at(node, key) + ": expected \"MIN..MAX\" or [MIN, MAX]");
      }
    } else if (key == "subjects") {
      const toml::array* a = node.as_array();
      if (!a) throw InputError(at(node, key) + ": expected an array of subject numbers");
      spec.subjects.clear();
      for (const toml::node& e : *a) spec.subjects.push_back(static_cast<int>(integer(e, key, 1, 255)));
    } else if (key == "balance") {
      spec.balance = boolean(node, key);
    } else if (key == "bodies") {
      spec.bodies = string(node, key);
      if (spec.bodies != "catalogue" && spec.bodies != "random" && spec.bodies != "per-scenario")
        throw InputError(at(node, key) + ": \"" + spec.bodies + "\" is not catalogue, random or per-scenario");
    } else if (key == "body_seed") {
      spec.body_seed = static_cast<uint64_t>(integer(node, key, 0, INT64_MAX));
    } else if (key == "body_count") {
      spec.body_count = static_cast<int>(integer(node, key, 1, kMaxRandomBodies));
    } else if (key == "what") {
      spec.what = string(node, key);
    } else if (key == "format") {
      spec.formats = strings(node, key);
    } else if (key == "image_format") {
      spec.image_format = string(node, key);
    } else if (key == "png_level") {
      spec.png_level = static_cast<int>(integer(node, key, 0, kMaxPngLevel));
    } else if (key == "compress") {
      spec.compress = boolean(node, key);
    } else if (key == "annotations") {
      spec.annotations = boolean(node, key);
    } else if (key == "tier") {
      spec.tier = string(node, key);
    } else if (key == "scenarios") {
      std::filesystem::path p(string(node, key));
      spec.scenarios = (p.is_relative() ? std::filesystem::path(dir) / p : p).string();
    } else if (const Knob* knob = find_knob(key)) {
      spec.set_knob_text(key, knob_value(*knob, node, at(node, key)), at(node, key));
    } else {
      std::string known =
          "count, seed, rule, pool, objects, subjects, bodies, body_count, body_seed, balance, what, format, "
          "image_format, "
          "png_level, compress, "
          "annotations, "
          "scenarios, tier";
      for (const Knob& k : portalsim::knobs()) known += ", " + k.key;
      throw InputError(at(node, key) + ": unknown key (" + known + ")");
    }
  }
}

GeneratorSpec generator_spec(const RunSpec& spec, const Catalogue& cat) {
  GeneratorSpec g;
  // The union of what the entries name, each object where it first appears (the order
  // the draws index); an object named twice by its own name is a slip and refused.
  std::vector<char> in_pool(cat.objects.size(), 0), named(cat.objects.size(), 0);
  for (const std::string& token : spec.pool) {
    const std::vector<int> set = parse_object_set(cat, token, spec.where("pool"), true);
    if (set.size() == 1 && !is_object_set_token(token) && normalise_name(token) != "all") {
      if (named[set[0]]) throw InputError(spec.where("pool") + ": \"" + token + "\" is listed twice");
      named[set[0]] = 1;
    }
    for (int o : set)
      if (!in_pool[o]) {
        in_pool[o] = 1;
        g.pool.push_back(o);
      }
  }
  g.min_objects = spec.min_objects;
  g.max_objects = spec.max_objects;
  for (int s : spec.subjects) {
    if (s < 1 || s > static_cast<int>(cat.subjects.size()))
      throw InputError(spec.where("subjects") + ": " + std::to_string(s) + " is out of range (1 to " +
                       std::to_string(cat.subjects.size()) + ")");
    g.subjects.push_back(s - 1);
  }
  // Compiled here too, so that a rule that does not parse is named where it was given
  // (the spec file's line, or --rule); the generator knows no file.
  if (!spec.rule.empty()) (void)ThreatRule(cat, spec.rule, spec.where("rule"));
  g.rule = spec.rule;
  g.balance = spec.balance;
  return g;
}

}  // namespace portalsim
