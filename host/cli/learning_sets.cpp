#include "cli/learning_sets.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "base/error.h"
#include "cli/features_table.h"
#include "sink/staging.h"

namespace portalsim::cli {

namespace fs = std::filesystem;

Table load_table(const std::string& path, const std::string& work, const std::string& tag, int block,
                 const std::string& catalogue) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    const std::string table = (fs::path(work) / (".features-" + tag + ".arff")).string();
    const FeaturesCount n = write_features({path}, table, "arff", block, catalogue);
    std::fprintf(stderr, "validate: %s: %zu scenario folders\n", path.c_str(), n.rows);
    Table t = read_arff(table);
    t.path = path;
    return t;
  }
  if (!fs::exists(path, ec)) throw InputError(path + ": no such file or folder");
  const std::string ext = lower(fs::path(path).extension().string());
  if (ext == ".arff") return read_arff(path);
  if (ext == ".csv") return read_csv(path);
  if (ext == ".h5") return read_h5_table(path);
  throw InputError(path + ": a feature table must be .arff, .csv or .h5, or a folder of scenario folders");
}

void check_same_attributes(const Table& sim, const Table& real) {
  for (size_t i = 0; i < std::max(sim.names.size(), real.names.size()); ++i) {
    if (i < sim.names.size() && i < real.names.size() && lower(sim.names[i]) == lower(real.names[i])) continue;
    if (i >= real.names.size())
      throw InputError(sim.path + ":" + std::to_string(sim.name_lines[i]) + ": attribute '" + sim.names[i] +
                       "' has no counterpart in " + real.path);
    if (i >= sim.names.size())
      throw InputError(real.path + ":" + std::to_string(real.name_lines[i]) + ": attribute '" + real.names[i] +
                       "' has no counterpart in " + sim.path);
    throw InputError(real.path + ":" + std::to_string(real.name_lines[i]) + ": attribute '" + real.names[i] +
                     "' differs from " + sim.path + ":" + std::to_string(sim.name_lines[i]) + " '" + sim.names[i] +
                     "'");
  }
}

void write_arff(const Table& t, const std::set<std::string>& classes, const std::string& path) {
  std::string s = "@relation validate\n";
  auto q = [](const std::string& n) {
    std::string r = "'";
    for (char c : n) r += c == '\'' ? std::string("\\'") : std::string(1, c);
    return r + "'";
  };
  for (size_t i = 0; i + 1 < t.names.size(); ++i) s += "@attribute " + q(t.names[i]) + " numeric\n";
  s += "@attribute class {";
  bool first = true;
  for (const auto& c : classes) {
    if (!first) s += ',';
    s += q(c);
    first = false;
  }
  s += "}\n@data\n";
  for (const auto& r : t.rows) {
    for (size_t i = 0; i + 1 < r.size(); ++i) s += r[i] + ",";
    s += q(r.back()) + "\n";
  }
  write_text_atomic(path, s);
}

WorkDir::WorkDir() {
  const char* tmp = std::getenv("TMPDIR");
  std::string tmpl = (fs::path(tmp && *tmp ? tmp : "/tmp") / "portalsim-validate-XXXXXX").string();
  if (!::mkdtemp(tmpl.data())) throw EnvironmentError(tmpl + ": cannot create a scratch folder");
  path = tmpl;
}

WorkDir::~WorkDir() {
  std::error_code ec;
  fs::remove_all(path, ec);
}

}  // namespace portalsim::cli
