#include "cli/weka.h"

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <sstream>

namespace portalsim::cli {

std::optional<double> j48_cv_accuracy(const std::string& arff, std::string& why) {
  const char* jar = "/usr/share/java/weka.jar";
  if (!std::filesystem::exists(jar)) {
    why = std::string(jar) + " not found (apt-get install weka)";
    return std::nullopt;
  }
  // The path goes through a shell: quote it.
  std::string quoted = "'";
  for (char c : arff) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  quoted += "'";
  const std::string cmd =
      "java -Xmx4g -cp " + std::string(jar) + " weka.classifiers.trees.J48 -x 10 -o -t " + quoted + " 2>&1";
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
    why = "WEKA J48 failed: " + out.substr(0, 300);
    return std::nullopt;
  }
  const size_t cv = out.find("=== Stratified cross-validation ===");
  const size_t line = out.find("Correctly Classified Instances", cv == std::string::npos ? 0 : cv);
  if (line == std::string::npos) {
    why = "no accuracy in WEKA's output";
    return std::nullopt;
  }
  std::istringstream in(out.substr(line + 30));
  double count = 0, percent = 0;
  in >> count >> percent;
  if (!in) {
    why = "unreadable accuracy in WEKA's output";
    return std::nullopt;
  }
  return percent;
}

}  // namespace portalsim::cli
