#include "cli/weka.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "base/embedded.h"
#include "cli/common.h"
#include "cli/learning_sets.h"
#include "sink/staging.h"

namespace portalsim::cli {

namespace {

bool on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  std::istringstream dirs(path);
  std::string dir;
  while (std::getline(dirs, dir, ':'))
    if (!dir.empty() && ::access((std::filesystem::path(dir) / program).c_str(), X_OK) == 0) return true;
  return false;
}

// Whether a line holds more than it should.
bool one_more(std::istringstream& fields) {
  std::string rest;
  return static_cast<bool>(fields >> rest);
}

}  // namespace

std::optional<std::string> weka_missing() {
  if (!std::filesystem::exists("/usr/share/java/weka.jar"))
    return "/usr/share/java/weka.jar not found (apt-get install weka)";
  // Weka.java runs as a single-file source program: the JDK's compiler, not a JRE alone.
  if (!on_path("java")) return "java not found on PATH (apt-get install default-jdk-headless)";
  return std::nullopt;
}

std::string weka_command(const std::string& dir, const char* heap) {
  const std::string program = (std::filesystem::path(dir) / "Weka.java").string();
  write_text_atomic(program, std::string(embedded::weka_program));
  return std::string("java -Xmx") + heap + " -cp /usr/share/java/weka.jar " + shell_quote(program);
}

std::optional<std::vector<std::vector<WekaScore>>> weka_scores(const std::vector<WekaJob>& jobs, std::string& why) {
  if (const auto missing = weka_missing()) {
    why = *missing;
    return std::nullopt;
  }
  const WorkDir work;
  const std::string list = (std::filesystem::path(work.path) / "jobs.tsv").string();
  std::string lines;
  for (const WekaJob& j : jobs) {
    lines += j.classifier + "\t" + j.train + "\t" + std::to_string(j.folds) + "\t" + std::to_string(j.seed);
    for (const std::string& t : j.tests) lines += "\t" + t;
    lines += "\n";
  }
  write_text_atomic(list, lines);
  const std::string errors = (std::filesystem::path(work.path) / "stderr.txt").string();
  const std::string cmd = weka_command(work.path, "4g") + " --jobs " + shell_quote(list) + " 2>" + shell_quote(errors);
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) {
    why = "cannot run java";
    return std::nullopt;
  }
  std::string out;
  char buf[4096];
  size_t got;
  while ((got = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, got);
  if (::pclose(p) != 0) {
    std::ifstream err(errors);
    const std::string text((std::istreambuf_iterator<char>(err)), std::istreambuf_iterator<char>());
    why = "WEKA failed: " + text.substr(0, 600);
    return std::nullopt;
  }
  // A line per job: "CORRECT MISCLASSIFIED" per test, or once for a cross-validation.
  std::vector<std::vector<WekaScore>> scores;
  std::istringstream in(out);
  for (const WekaJob& j : jobs) {
    std::string line;
    std::getline(in, line);
    std::istringstream fields(line);
    auto& s = scores.emplace_back(std::max<size_t>(j.tests.size(), 1));
    for (WekaScore& one : s) fields >> one.correct >> one.misclassified;
    if (!fields || one_more(fields)) {
      why = "unreadable scores in WEKA's output: " + out.substr(0, 600);
      return std::nullopt;
    }
  }
  return scores;
}

}  // namespace portalsim::cli
