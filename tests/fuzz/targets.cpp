#include "targets.h"

#include <unistd.h>

#include <cstdio>
#include <stdexcept>
#include <string_view>

#include "assets/image_io.h"
#include "base/error.h"
#include "scene/catalogue.h"
#include "scene/generator.h"
#include "schedule/run_spec.h"
#include "sink/folder_reader.h"

namespace portalsim::fuzz {

namespace {

void catalogue(std::string_view text) { (void)parse_catalogue(text, "<fuzz>", "", ""); }

void spec(std::string_view text) {
  RunSpec s;
  parse_spec(text, "<fuzz>", s);
  s.validate();
}

void scenarios(std::string_view text) {
  static const Catalogue cat = default_catalogue();
  (void)parse_scenario_list(cat, text, "<fuzz>");
}

// metal.txt and threat.txt, the two small tables a scenario folder carries.
void feature_table(std::string_view text) {
  bool parsed = false;
  try {
    (void)parse_metal_text(text, "<fuzz>");
    parsed = true;
  } catch (const InputError&) {
  }
  try {
    (void)parse_threat_text(text, "<fuzz>");
  } catch (const InputError&) {
    if (!parsed) throw;
  }
}

// OpenImageIO reads files by name: the bytes go to a file of this process's own.
void image(std::string_view bytes) {
  static const std::string path = "/tmp/portalsim-fuzz-image-" + std::to_string(::getpid());
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw std::runtime_error("cannot write " + path);
  std::fwrite(bytes.data(), 1, bytes.size(), f);
  std::fclose(f);
  (void)read_image(path, "<fuzz>");
}

}  // namespace

const std::vector<std::string>& target_names() {
  static const std::vector<std::string> names{"catalogue", "spec", "scenarios", "feature_table", "image"};
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
    else
      throw std::logic_error("no fuzz target " + target);
  } catch (const InputError&) {
    return false;
  }
  return true;
}

}  // namespace portalsim::fuzz
