// Everything that decides a data set's contents: the identity recorded in the manifest
// and checked on --resume. Batch size, threads and backend are not part of it: they
// never change the data.
#pragma once
#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "assets/png_writer.h"
#include "plan/plan.h"
#include "scene/bodies.h"
#include "scene/generator.h"

namespace portalsim {

struct RunSpec {
  uint64_t count = 1000;
  uint64_t seed = 0;
  std::vector<std::string> pool;  // names, class:NAME, family:NAME, all, as given; empty = default_pool
  int min_objects = 0, max_objects = 4;
  std::vector<int> subjects;  // 1-based; empty = all
  // "catalogue": the catalogue's subjects; "random": body_count bodies drawn from the seed
  // (scene/bodies.h), which replace them; "per-scenario": a body of its own for every
  // scenario, drawn from the seed and its index (scene/bodies.h, use_page_bodies).
  std::string bodies = "catalogue";
  int body_count = 0;  // 0: kDefaultRandomBodies where the bodies are random
  int random_bodies() const { return bodies == "random" ? (body_count ? body_count : kDefaultRandomBodies) : 0; }
  bool per_scenario_bodies() const { return bodies == "per-scenario"; }
  bool drawn_bodies() const { return random_bodies() > 0 || per_scenario_bodies(); }
  // The seed the random bodies are drawn from: the run's, unless given apart (to test on
  // the training bodies with other scenarios, or on other bodies with the same ones).
  std::optional<uint64_t> body_seed;
  uint64_t bodies_seed() const { return body_seed.value_or(seed); }
  std::string rule;
  bool balance = false;
  std::string scenarios;          // explicit scenario list (CSV); replaces the generator
  std::string what = "features";  // features | images | both
  std::vector<std::string> formats{"arff"};
  std::string image_format = "png";
  int png_level = kDefaultPngLevel;          // deflate level of image folders' PNGs (png_writer.h)
  bool compress = false;                     // gzip data.h5's datasets (--format h5)
  bool annotations = false;                  // boxes and masks: annotations.json, YOLO, mask images
  std::string tier = "standard";             // fast | standard | exact; fidelity knobs override it
  std::map<std::string, std::string> knobs;  // the knobs given (plan/knobs.h), by key, as text
  // The model and fidelity: the tier's, then every given knob; the model's seed is `seed`.
  Plan settings() const;
  // Where each key came from in a spec file ("spec.toml:3: pool"); keys given on the
  // command line are named by their flag instead.
  std::map<std::string, std::string> origin;
  std::string where(const std::string& key) const {
    auto it = origin.find(key);
    if (it != origin.end()) return it->second;
    std::string flag = "--" + key;
    for (char& c : flag)
      if (c == '_') c = '-';
    return flag;
  }

  bool wants_features() const { return what != "images"; }
  bool wants_images() const { return what != "features"; }
  bool has_format(const std::string& f) const { return std::find(formats.begin(), formats.end(), f) != formats.end(); }
  // Images go to tensors instead of image folders: data.h5 (format h5), or <view>.npy
  // (format npy with --what images; with --what both, npy is the feature table).
  bool npy_image_tensors() const { return what == "images" && has_format("npy"); }
  bool image_tensors() const { return wants_images() && (has_format("h5") || npy_image_tensors()); }
  // Images go to images/<index>/ folders.
  bool image_folders() const { return wants_images() && !image_tensors(); }
  nlohmann::json to_json() const;
  // Sets a knob (checked at once; throws InputError naming `where`).
  void set_knob_text(const std::string& key, const std::string& text, const std::string& where);
  // Checks values that need no catalogue; throws InputError naming the option.
  void validate() const;
};

// Reads a TOML spec (keys as the long options: count, seed, rule, pool, objects,
// subjects, balance, what, format, image_format, png_level, scenarios, tier and every knob's key)
// over `spec`. Errors name the file, line and key.
void read_spec_file(const std::string& path, RunSpec& spec);
// The same from text already read; `path` names it in errors.
void parse_spec(std::string_view text, const std::string& path, RunSpec& spec);
// "a, b,c" -> {"a", "b", "c"}: comma-separated names, spaces dropped, empty items skipped.
std::vector<std::string> split_list(const std::string& text);
// "MIN..MAX" or "N".
void parse_object_range(const std::string& text, const std::string& where, RunSpec& spec);

GeneratorSpec generator_spec(const RunSpec& spec, const Catalogue& cat);

}  // namespace portalsim
