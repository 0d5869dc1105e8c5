#include "cli/weka.h"

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <sstream>

namespace portalsim::cli {

namespace {

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace

std::optional<std::string> weka_missing() {
  if (!std::filesystem::exists("/usr/share/java/weka.jar"))
    return "/usr/share/java/weka.jar not found (apt-get install weka)";
  if (std::system("command -v java >/dev/null 2>&1") != 0)
    return "java not found on PATH (apt-get install default-jre-headless)";
  return std::nullopt;
}

std::optional<WekaScore> weka_score(const std::string& classifier, const std::string& train, const std::string& test,
                                    int folds, int seed, std::string& why) {
  const char* jar = "/usr/share/java/weka.jar";
  if (const auto missing = weka_missing()) {
    why = *missing;
    return std::nullopt;
  }
  std::string cmd = "java -Xmx4g -cp " + std::string(jar) + " " + classifier + " -o -t " + quote(train);
  if (test.empty())
    cmd += " -x " + std::to_string(folds) + " -s " + std::to_string(seed);
  else
    cmd += " -T " + quote(test);
  cmd += " 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) {
    why = "cannot run java";
    return std::nullopt;
  }
  std::string out;
  char buf[4096];
  size_t got;
  while ((got = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, got);
  const int status = ::pclose(p);
  if (status != 0) {
    why = "WEKA " + classifier + " failed: " + out.substr(0, 300);
    return std::nullopt;
  }
  const char* section = test.empty() ? "=== Stratified cross-validation ===" : "=== Error on test data ===";
  const size_t at = out.find(section);
  const size_t ok = at == std::string::npos ? at : out.find("Correctly Classified Instances", at);
  const size_t bad = at == std::string::npos ? at : out.find("Incorrectly Classified Instances", at);
  if (ok == std::string::npos || bad == std::string::npos) {
    why = "no accuracy in WEKA's output";
    return std::nullopt;
  }
  WekaScore score;
  double count = 0;
  std::istringstream ok_in(out.substr(ok + 30)), bad_in(out.substr(bad + 32));
  ok_in >> count >> score.correct_percent;
  bad_in >> score.misclassified;
  if (!ok_in || !bad_in) {
    why = "unreadable accuracy in WEKA's output";
    return std::nullopt;
  }
  return score;
}

std::optional<double> j48_cv_accuracy(const std::string& arff, std::string& why) {
  auto s = weka_score("weka.classifiers.trees.J48", arff, "", 10, 1, why);
  if (!s) return std::nullopt;
  return s->correct_percent;
}

}  // namespace portalsim::cli
