#include "targets.h"

#include <unistd.h>

#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "assets/image_io.h"
#include "base/error.h"
#include "cli/validate_tables.h"
#include "scene/catalogue.h"
#include "scene/generator.h"
#include "scene/scenario_list.h"
#include "schedule/run_spec.h"
#include "schedule/run_state.h"
#include "serve/request.h"
#include "sink/folder_reader.h"

namespace portalsim::fuzz {

namespace {

void catalogue(std::string_view text) { (void)parse_catalogue(text, "<fuzz>", "", ""); }

// A spec, its checks, and its generator's (the pool, subjects and rule against the catalogue).
void spec(std::string_view text) {
  static const Catalogue cat = default_catalogue();
  RunSpec s;
  parse_spec(text, "<fuzz>", s);
  s.validate();
  (void)generator_spec(s, cat);
}

void scenarios(std::string_view text) {
  static const Catalogue cat = default_catalogue();
  (void)parse_scenario_list(cat, text, "<fuzz>");
}

// metal.txt and threat.txt, the two small tables a scenario folder carries.
void feature_table(std::string_view text) {
  bool parsed = false;
  try {
    (void)parse_metal_text(text, "<fuzz>", 19);
    parsed = true;
  } catch (const InputError&) {
  }
  try {
    (void)parse_threat_text(text, "<fuzz>");
  } catch (const InputError&) {
    if (!parsed) throw;
  }
}

// OpenImageIO and libhdf5 read files by name: the bytes go to a file of this process's own.
std::string as_file(std::string_view bytes, const char* kind) {
  const std::string path = "/tmp/portalsim-fuzz-" + std::string(kind) + "-" + std::to_string(::getpid());
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw std::runtime_error("cannot write " + path);
  std::fwrite(bytes.data(), 1, bytes.size(), f);
  std::fclose(f);
  return path;
}

void image(std::string_view bytes) { (void)read_image(as_file(bytes, "image"), "<fuzz>"); }

// validate's feature tables.
void arff(std::string_view text) {
  std::istringstream in{std::string(text)};
  (void)cli::parse_arff(in, "<fuzz>");
}

void csv(std::string_view text) {
  std::istringstream in{std::string(text)};
  (void)cli::parse_csv(in, "<fuzz>");
}

void h5(std::string_view bytes) { (void)cli::read_h5_table(as_file(bytes, "h5")); }

// A run's checkpoint as --resume reads it: the files' states and the identity compared.
void checkpoint(std::string_view text) {
  const nlohmann::json c = parse_checkpoint(text, "<fuzz>");
  uint64_t bytes = c["next"].get<uint64_t>() + c["positive"].get<uint64_t>() + c["negative"].get<uint64_t>();
  for (const nlohmann::json& f : c["files"])
    bytes += f["name"].get<std::string>().size() + f["bytes"].get<uint64_t>() + f["xxh3"].get<uint64_t>();
  (void)bytes;
  (void)c.value("identity", nlohmann::json::object()).dump();
}

// A finished run's manifest as --resume and merge read it.
void manifest(std::string_view text) {
  const nlohmann::json m = parse_manifest(text, "<fuzz>");
  uint64_t sum = m["shard"]["begin"].get<uint64_t>() + m["shard"]["end"].get<uint64_t>() + manifest_total(m["spec"]);
  for (const nlohmann::json& o : m["outputs"]) sum += o.at("name").get<std::string>().size();
  for (const char* k : {"portalsim", "catalogue", "spec"}) sum += m.value(k, nlohmann::json()).dump().size();
  (void)sum;
}

// The body of a POST to serve's API, and the folder name it gives.
void request(std::string_view text) {
  static const Catalogue cat = default_catalogue();
  const Request r = parse_request(cat, text);
  if (!r.name.empty()) (void)check_name(r.name, "name");
}

}  // namespace

const std::vector<std::string>& target_names() {
  static const std::vector<std::string> names{"catalogue", "spec", "scenarios",  "feature_table", "image",  "arff",
                                              "csv",       "h5",   "checkpoint", "manifest",      "request"};
  return names;
}

bool run_target(const std::string& target, const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    if (target == "catalogue")
      catalogue(text);
    else if (target == "spec")
      spec(text);
    else if (target == "scenarios")
      scenarios(text);
    else if (target == "feature_table")
      feature_table(text);
    else if (target == "image")
      image(text);
    else if (target == "arff")
      arff(text);
    else if (target == "csv")
      csv(text);
    else if (target == "h5")
      h5(text);
    else if (target == "checkpoint")
      checkpoint(text);
    else if (target == "manifest")
      manifest(text);
    else if (target == "request")
      request(text);
    else
      throw std::logic_error("no fuzz target " + target);
  } catch (const InputError&) {
    return false;
  } catch (const OutputError&) {  // a run's own state files (checkpoint) are its output
    return false;
  }
  return true;
}

}  // namespace portalsim::fuzz
