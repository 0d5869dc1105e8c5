// `portalsim generate` and `portalsim features` as a user meets them: every test runs the real
// binary in its own temporary folder and checks its exit status, what it printed, and the data
// set it left on disk (tables, scenario lists, image folders, manifest, checkpoints).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "assets/image_io.h"
#include "run_binary.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Args = std::vector<std::string>;
using RunResult = portalsim::test::Result;
using Started = portalsim::test::Running;
const auto& read_all = portalsim::test::slurp;
const auto& write_all = portalsim::test::spit;

// ---------------------------------------------------------------------------------------------
// Running the binary (the same approach as cli_test.cpp).

// A fresh folder under /tmp for one test: w/ is the workspace, cap/ holds captured output.
using GenTempDir = portalsim::test::TempDir;

using portalsim::test::has;

const auto& split_on = portalsim::test::split;

std::string describe_run(const RunResult& r) { return portalsim::test::describe(r, 4000); }

Started start_program(const GenTempDir& t, const std::string& program, const Args& args) {
  return portalsim::test::start_program(t.cap(), program, args);
}

Started start_ps(const GenTempDir& t, const Args& args) { return start_program(t, portalsim::test::kBinary, args); }

// Signals a started run, never anything else (a failed start has no pid: kill(-1) would hit
// every process we may signal).
void send_signal(const Started& r, int sig) {
  if (r.pid > 0) ::kill(r.pid, sig);
}

using portalsim::test::has_ended;

RunResult wait_for(const Started& r, int limit_s = 120) { return portalsim::test::finish(r, limit_s); }

RunResult run_ps(const GenTempDir& t, const Args& args) { return wait_for(start_ps(t, args)); }

const auto& run_ps_all = portalsim::test::run_all;

// `portalsim generate ARGS --out OUT`.
Args gen(const Args& args, const fs::path& out) { return portalsim::test::with_out("generate", args, out); }

Args plus(Args a, const Args& more) {
  a.insert(a.end(), more.begin(), more.end());
  return a;
}

// ARGS with option NAME set to VALUE (replaced where given, appended otherwise).
Args with(Args a, const std::string& name, const std::string& value) {
  for (size_t i = 0; i + 1 < a.size(); ++i)
    if (a[i] == name) {
      a[i + 1] = value;
      return a;
    }
  a.push_back(name);
  a.push_back(value);
  return a;
}

const auto& ExpectOk = portalsim::test::expect_success;

const auto& entries_of = portalsim::test::names_in;

// Every regular file under `dir`, hidden ones included, as sorted relative paths.
std::vector<std::string> files_under(const fs::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec))
    if (it->is_regular_file()) names.push_back(fs::relative(it->path(), dir).string());
  std::sort(names.begin(), names.end());
  return names;
}

// Folder contents as path -> bytes (for "left untouched" checks on small folders).
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> m;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec))
    m[fs::relative(it->path(), dir).string()] = it->is_regular_file() ? read_all(it->path()) : std::string("<dir>");
  return m;
}

// Two output folders hold the same files with the same bytes (large files are not printed).
void ExpectSameTree(const fs::path& a, const fs::path& b) {
  const std::vector<std::string> fa = files_under(a), fb = files_under(b);
  ASSERT_EQ(fa, fb) << a << " and " << b << " hold different files";
  ASSERT_FALSE(fa.empty()) << a << " is empty";
  int differing = 0;
  for (const std::string& f : fa) {
    const std::string x = read_all(a / f), y = read_all(b / f);
    if (x != y && ++differing <= 5)
      ADD_FAILURE() << f << " differs between " << a << " and " << b << " (" << x.size() << " vs " << y.size()
                    << " bytes)";
  }
  EXPECT_EQ(differing, 0) << "files differing between " << a << " and " << b;
}

// One generate command that must be refused, with OUT absent and (also_existing) OUT empty.
using Refusal = portalsim::test::Rejection;
const auto& ExpectRefused = portalsim::test::expect_clean_failure;
const auto& stderr_messages = portalsim::test::message_lines;

void ExpectAllRefused(const GenTempDir& t, const std::vector<Refusal>& cases) {
  portalsim::test::expect_all_rejected(t, "generate", cases);
}

// ---------------------------------------------------------------------------------------------
// Reading the outputs.

// The lines of a text file without the final newline's empty string.
std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> l = split_on(text, '\n');
  if (!l.empty() && l.back().empty()) l.pop_back();
  return l;
}

// CSV data rows (every line after the header).
std::vector<std::string> csv_rows(const std::string& text) {
  std::vector<std::string> l = lines_of(text);
  if (!l.empty()) l.erase(l.begin());
  return l;
}

// ARFF data rows (every line after @data).
std::vector<std::string> arff_rows(const std::string& text) {
  std::vector<std::string> l = lines_of(text), rows;
  bool data = false;
  for (const std::string& s : l) {
    if (data)
      rows.push_back(s);
    else if (s == "@data")
      data = true;
  }
  return rows;
}

json read_json(const fs::path& p) {
  const json j = json::parse(read_all(p), nullptr, false);
  if (j.is_discarded()) ADD_FAILURE() << p << " is not valid JSON";
  return j;
}

struct Npy {
  bool ok = false;
  std::string why;
  size_t header_bytes = 0;  // magic .. the dict's final newline
  std::string dict;
  uint64_t rows = 0, cols = 0;
  std::vector<float> data;
};

// Parses an .npy file: version 1.0, little-endian float32, C order, 2-D.
Npy parse_npy(const std::string& bytes) {
  Npy n;
  if (bytes.size() < 10 || bytes.compare(0, 6, "\x93NUMPY") != 0) {
    n.why = "no \\x93NUMPY magic";
    return n;
  }
  if (bytes[6] != 1 || bytes[7] != 0) {
    n.why = "version is not 1.0";
    return n;
  }
  const size_t len =
      static_cast<unsigned char>(bytes[8]) | (static_cast<size_t>(static_cast<unsigned char>(bytes[9])) << 8);
  n.header_bytes = 10 + len;
  if (bytes.size() < n.header_bytes) {
    n.why = "shorter than its header";
    return n;
  }
  n.dict = bytes.substr(10, len);
  if (n.dict.empty() || n.dict.back() != '\n') {
    n.why = "header does not end with a newline";
    return n;
  }
  if (!has(n.dict, "'descr': '<f4'")) {
    n.why = "descr is not '<f4': " + n.dict;
    return n;
  }
  if (!has(n.dict, "'fortran_order': False")) {
    n.why = "not C order: " + n.dict;
    return n;
  }
  const size_t s = n.dict.find("'shape': (");
  if (s == std::string::npos) {
    n.why = "no shape: " + n.dict;
    return n;
  }
  unsigned long long r = 0, c = 0;
  if (std::sscanf(n.dict.c_str() + s, "'shape': (%llu, %llu)", &r, &c) != 2) {
    n.why = "shape is not (N, C): " + n.dict;
    return n;
  }
  n.rows = r;
  n.cols = c;
  const size_t payload = bytes.size() - n.header_bytes;
  if (payload != n.rows * n.cols * sizeof(float)) {
    n.why = std::string("data is ") + std::to_string(payload) + std::string(" bytes, shape says ") +
            std::to_string(n.rows * n.cols * 4);
    return n;
  }
  n.data.resize(static_cast<size_t>(n.rows * n.cols));
  std::memcpy(n.data.data(), bytes.data() + n.header_bytes, payload);  // the test host is little-endian
  n.ok = true;
  return n;
}

using portalsim::test::checkpoint_next;

// Polls the run's checkpoint until "next" reaches `at_least` (-1: the checkpoint just exists).
// False when the run ended first or the (scaled) limit passed.
bool wait_for_checkpoint(const Started& r, const fs::path& dir, long long at_least) {
  // Generous: under the sanitizers on a loaded 2-core machine the kernel build alone can
  // take a minute.
  bool reached = false;
  portalsim::test::wait_until(
      [&] {
        const long long next = checkpoint_next(dir);
        reached = next >= 0 && next >= at_least;
        return reached || has_ended(r);
      },
      300, 5);
  return reached;
}

// ---------------------------------------------------------------------------------------------
// 1. ARFF for WEKA.

std::string find_on_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  for (const std::string& d : split_on(path ? path : "/usr/bin:/bin", ':')) {
    if (d.empty()) continue;
    const fs::path p = fs::path(d) / name;
    if (::access(p.c_str(), X_OK) == 0) return p.string();
  }
  return "";
}

TEST(GenerateArff, HeaderRowsAndWekaLearnsTheGunRule) {
  GenTempDir t;
  const fs::path out = t.w() / "out";
  const RunResult r = run_ps(
      t, gen({"--count", "400", "--seed", "1", "--rule", "gun", "--balance", "--format", "arff,csv", "--quiet"}, out));
  ExpectOk(r);
  EXPECT_EQ(entries_of(out), (std::vector<std::string>{"README.md", "croissant.json", "features.arff", "features.csv",
                                                       "manifest.json", "scenarios.csv"}));
  const std::string arff = read_all(out / "features.arff");
  const std::vector<std::string> lines = lines_of(arff);
  ASSERT_FALSE(lines.empty());
  std::vector<std::string> attributes;
  bool relation = false, data = false, class_attr = false;
  size_t data_rows = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    const std::string& l = lines[i];
    if (data) {
      ++data_rows;
      const std::vector<std::string> f = split_on(l, ',');
      ASSERT_EQ(f.size(), attributes.size()) << "data row " << data_rows << " has a wrong field count";
      EXPECT_TRUE(f.back() == "positive" || f.back() == "negative") << "row " << data_rows << ": " << f.back();
      continue;
    }
    if (l.rfind("@relation ", 0) == 0) {
      relation = true;
    } else if (l == "@attribute class {positive,negative}") {
      class_attr = true;
      attributes.push_back("class");
    } else if (l.rfind("@attribute ", 0) == 0) {
      EXPECT_FALSE(class_attr) << "line " << i + 1 << ": attributes after the class";
      const std::vector<std::string> f = split_on(l, ' ');
      ASSERT_EQ(f.size(), 3u) << "line " << i + 1 << ": " << l;
      EXPECT_EQ(f[2], "numeric") << "line " << i + 1 << ": " << l;
      attributes.push_back(f[1]);
    } else if (l == "@data") {
      data = true;
    } else {
      EXPECT_TRUE(l.empty() || l[0] == '%') << "line " << i + 1 << " is not ARFF: " << l;
    }
  }
  EXPECT_TRUE(relation) << "no @relation line";
  EXPECT_TRUE(class_attr) << "no @attribute class {positive,negative}";
  EXPECT_TRUE(data) << "no @data line";
  EXPECT_EQ(attributes.size(), 2u * 20 * 20 + 13 + 19 + 1);
  EXPECT_EQ(std::set<std::string>(attributes.begin(), attributes.end()).size(), attributes.size())
      << "attribute names must be distinct";
  EXPECT_EQ(data_rows, 400u);
  // The CSV has the same names and the same rows.
  const std::string csv = read_all(out / "features.csv");
  const std::vector<std::string> csv_lines = lines_of(csv);
  ASSERT_FALSE(csv_lines.empty());
  EXPECT_EQ(split_on(csv_lines[0], ','), attributes) << "the CSV header names the ARFF attributes";
  EXPECT_TRUE(csv_rows(csv) == arff_rows(arff)) << "the CSV and ARFF data rows differ";

  const fs::path jar = "/usr/share/java/weka.jar";
  const std::string java = find_on_path("java");
  ASSERT_FALSE(java.empty()) << "java is not installed (tools/setup.sh installs it)";
  ASSERT_TRUE(fs::exists(jar)) << jar << " is not installed (tools/setup.sh installs weka)";
  const RunResult w = wait_for(start_program(
      t, java, {"-cp", jar.string(), "weka.classifiers.trees.J48", "-t", (out / "features.arff").string()}));
  ASSERT_TRUE(w.exited && w.status == 0) << describe_run(w);
  ASSERT_TRUE(has(w.out, "Correctly Classified Instances")) << describe_run(w);
  // With -t alone WEKA prints the training-set figures, then the 10-fold cross-validation's.
  const size_t cv = w.out.find("=== Stratified cross-validation ===");
  ASSERT_NE(cv, std::string::npos) << describe_run(w);
  const size_t at = w.out.find("Correctly Classified Instances", cv);
  ASSERT_NE(at, std::string::npos) << describe_run(w);
  std::istringstream s(w.out.substr(at + std::strlen("Correctly Classified Instances")));
  long long correct = -1;
  double percent = -1;
  s >> correct >> percent;
  ASSERT_TRUE(s) << describe_run(w);
  RecordProperty("weka_j48_cv_percent", std::to_string(percent));
  EXPECT_GT(percent, 80.0) << "J48 should learn 'gun' from the metal zones; cross-validated accuracy " << percent
                           << "%";
}

// ---------------------------------------------------------------------------------------------
// 2. CSV header and NPY.

TEST(GenerateTables, NpyParsesAndEqualsTheCsv) {
  GenTempDir t;
  const fs::path out = t.w() / "out";
  ExpectOk(run_ps(t, gen({"--count", "300", "--seed", "5", "--rule", "gun|iron-rod", "--metal-noise", "3", "--format",
                          "csv,npy", "--quiet"},
                         out)));
  EXPECT_EQ(entries_of(out),
            (std::vector<std::string>{"README.md", "croissant.json", "features.columns.txt", "features.csv",
                                      "features.npy", "manifest.json", "scenarios.csv"}));
  const std::vector<std::string> csv = lines_of(read_all(out / "features.csv"));
  ASSERT_EQ(csv.size(), 301u);
  const std::vector<std::string> header = split_on(csv[0], ',');
  const size_t C = header.size();
  EXPECT_EQ(C, 2u * 20 * 20 + 13 + 19 + 1);
  EXPECT_EQ(header.back(), "class");
  EXPECT_EQ(lines_of(read_all(out / "features.columns.txt")), header)
      << "features.columns.txt names the npy columns, one per line, as the CSV header does";

  const std::string bytes = read_all(out / "features.npy");
  const Npy npy = parse_npy(bytes);
  ASSERT_TRUE(npy.ok) << npy.why;
  EXPECT_EQ(npy.header_bytes % 64, 0u) << "the npy header should be padded to 64 bytes";
  EXPECT_EQ(npy.rows, 300u);
  EXPECT_EQ(npy.cols, C);
  const size_t F = C - 1 - 19;  // image features, then 19 zones, then the class
  int mismatches = 0;
  for (size_t i = 0; i < 300 && mismatches < 10; ++i) {
    const std::vector<std::string> f = split_on(csv[i + 1], ',');
    ASSERT_EQ(f.size(), C) << "CSV row " << i;
    const float* row = npy.data.data() + i * C;
    for (size_t k = 0; k < C; ++k) {
      if (k < F) {
        char* end = nullptr;
        const double v = std::strtod(f[k].c_str(), &end);
        ASSERT_TRUE(end && *end == '\0' && !f[k].empty()) << "row " << i << " column " << header[k] << ": " << f[k];
        if (std::fabs(v - static_cast<double>(row[k])) > 5e-5 + 1e-9) {
          ++mismatches;
          ADD_FAILURE() << "row " << i << " column " << header[k] << ": csv " << f[k] << ", npy " << row[k];
        }
      } else if (k < C - 1) {
        if (std::to_string(static_cast<int>(row[k])) != f[k] || row[k] != std::floor(row[k])) {
          ++mismatches;
          ADD_FAILURE() << "row " << i << " zone " << header[k] << ": csv " << f[k] << ", npy " << row[k];
        }
      } else {
        const float want = f[k] == "positive" ? 1.0f : f[k] == "negative" ? 0.0f : -1.0f;
        if (row[k] != want) {
          ++mismatches;
          ADD_FAILURE() << "row " << i << " class: csv " << f[k] << ", npy " << row[k];
        }
      }
    }
  }
  EXPECT_EQ(mismatches, 0);
  // The rule mixes classes here; both must show up.
  json m = read_json(out / "manifest.json");
  EXPECT_EQ(m["count"], 300);
  EXPECT_GT(m["classes"]["positive"].get<int>(), 0);
  EXPECT_GT(m["classes"]["negative"].get<int>(), 0);
}

// ---------------------------------------------------------------------------------------------
// 3. Determinism.

TEST(GenerateDeterminism, FeaturesDoNotDependOnBatchOrThreads) {
  GenTempDir t;
  const Args spec{"--count",   "1500",          "--seed", "7",        "--rule",       "gun",
                  "--balance", "--metal-noise", "3",      "--format", "arff,csv,npy", "--quiet"};
  const std::vector<Args> variants{{"--batch", "1", "--threads", "1"},
                                   {"--batch", "7", "--threads", "2"},
                                   {"--batch", "1000", "--threads", "2"},
                                   {"--batch", "1000", "--threads", "1"},
                                   {"--threads", "2"},
                                   {"--backend", "opencl"}};
  std::vector<Args> commands;
  for (size_t i = 0; i < variants.size(); ++i)
    commands.push_back(gen(plus(spec, variants[i]), t.w() / (std::string("v") + std::to_string(i))));
  Args other = spec;
  other[3] = "8";
  commands.push_back(gen(other, t.w() / "seed8"));
  const std::vector<RunResult> r = run_ps_all(t, commands);
  for (const RunResult& x : r) ExpectOk(x);
  ASSERT_EQ(entries_of(t.w() / "v0"),
            (std::vector<std::string>{"README.md", "croissant.json", "features.arff", "features.columns.txt",
                                      "features.csv", "features.npy", "manifest.json", "scenarios.csv"}));
  const std::string manifest = read_all(t.w() / "v0" / "manifest.json");
  EXPECT_FALSE(has(manifest, "second")) << "the manifest must not hold timings:\n" << manifest;
  for (size_t i = 1; i < variants.size(); ++i) {
    SCOPED_TRACE(r[i].command);
    ExpectSameTree(t.w() / "v0", t.w() / (std::string("v") + std::to_string(i)));
  }
  // Another seed: other scenarios, other features (rows compared without the class).
  const std::vector<std::string> a = csv_rows(read_all(t.w() / "v0" / "features.csv")),
                                 b = csv_rows(read_all(t.w() / "seed8" / "features.csv"));
  ASSERT_EQ(a.size(), 1500u);
  ASSERT_EQ(b.size(), 1500u);
  size_t same = 0;
  for (size_t i = 0; i < a.size(); ++i) same += a[i] == b[i];
  EXPECT_LT(same, 750u) << "seeds 7 and 8 gave the same feature row for " << same << " of 1500 scenarios";
  EXPECT_NE(read_all(t.w() / "v0" / "scenarios.csv"), read_all(t.w() / "seed8" / "scenarios.csv"));
  // Balanced: even indices are threats.
  const std::vector<std::string> sc = csv_rows(read_all(t.w() / "v0" / "scenarios.csv"));
  ASSERT_EQ(sc.size(), 1500u);
  for (size_t i = 0; i < sc.size(); ++i) {
    const std::vector<std::string> f = split_on(sc[i], ',');
    ASSERT_EQ(f.size(), 16u) << sc[i];
    EXPECT_EQ(f[0], std::to_string(i));
    ASSERT_EQ(f[15], i % 2 == 0 ? "yes" : "no") << "row " << i << ": " << sc[i];
  }
}

TEST(GenerateDeterminism, ImagesAndNoisyFeaturesDoNotDependOnBatchOrThreads) {
  GenTempDir t;
  // With annotations: every file of an image folder, masks and YOLO boxes too.
  const Args spec{"--count",       "20", "--seed",        "11", "--what",   "both",    "--rule",        "gun",
                  "--pixel-noise", "2",  "--metal-noise", "3",  "--format", "csv,npy", "--annotations", "--quiet"};
  const std::vector<Args> variants{
      {"--batch", "1", "--threads", "1"}, {"--batch", "7", "--threads", "2"}, {"--batch", "1000", "--threads", "2"}};
  std::vector<Args> commands;
  for (size_t i = 0; i < variants.size(); ++i)
    commands.push_back(gen(plus(spec, variants[i]), t.w() / (std::string("v") + std::to_string(i))));
  const std::vector<RunResult> r = run_ps_all(t, commands);
  for (const RunResult& x : r) ExpectOk(x);
  const fs::path v0 = t.w() / "v0";
  std::vector<std::string> folders;
  for (int i = 0; i < 20; ++i) {
    char name[16];
    std::snprintf(name, sizeof name, "%08d", i);
    folders.push_back(name);
  }
  EXPECT_EQ(entries_of(v0 / "images"), folders);
  EXPECT_EQ(entries_of(v0 / "images" / "00000013"),
            (std::vector<std::string>{"features.csv", "ir.png", "ir.txt", "lower.png", "lower.txt", "mask_ir.png",
                                      "mask_lower.png", "mask_upper.png", "metal.txt", "threat.txt", "upper.png",
                                      "upper.txt"}));
  for (size_t i = 1; i < variants.size(); ++i) {
    SCOPED_TRACE(r[i].command);
    ExpectSameTree(v0, t.w() / (std::string("v") + std::to_string(i)));
  }
  // Each scenario folder's features.csv row is that scenario's row of the table.
  const std::vector<std::string> rows = csv_rows(read_all(v0 / "features.csv"));
  ASSERT_EQ(rows.size(), 20u);
  for (size_t i = 0; i < 20; ++i)
    EXPECT_EQ(csv_rows(read_all(v0 / "images" / folders[i] / "features.csv")), std::vector<std::string>{rows[i]})
        << folders[i];
  json m = read_json(v0 / "manifest.json");
  EXPECT_EQ(m["images"]["count"], 20);
}

// ---------------------------------------------------------------------------------------------
// 4. Shards.

TEST(GenerateShards, RowsConcatenateToTheWholeRun) {
  GenTempDir t;
  const Args spec{"--count",   "1000",     "--seed",       "3",      "--rule", "gun",
                  "--balance", "--format", "csv,npy,arff", "--quiet"};
  std::vector<Args> commands{gen(spec, t.w() / "whole")};
  for (int i = 0; i < 3; ++i)
    commands.push_back(
        gen(plus(spec, {"--shard", std::to_string(i) + "/3"}), t.w() / (std::string("s") + std::to_string(i))));
  const std::vector<RunResult> r = run_ps_all(t, commands);
  for (const RunResult& x : r) ExpectOk(x);
  const fs::path whole = t.w() / "whole";
  const uint64_t bounds[4] = {0, 333, 666, 1000};

  std::vector<std::string> csv, arff, scen;
  std::string npy_data;
  uint64_t positive = 0, negative = 0;
  for (int i = 0; i < 3; ++i) {
    SCOPED_TRACE(std::string("shard ") + std::to_string(i) + "/3");
    const fs::path s = t.w() / (std::string("s") + std::to_string(i));
    const std::string c = read_all(s / "features.csv"), a = read_all(s / "features.arff"),
                      sc = read_all(s / "scenarios.csv");
    EXPECT_EQ(lines_of(c).at(0), lines_of(read_all(whole / "features.csv")).at(0)) << "every shard has the header";
    EXPECT_EQ(lines_of(sc).at(0), lines_of(read_all(whole / "scenarios.csv")).at(0));
    for (const std::string& l : csv_rows(c)) csv.push_back(l);
    for (const std::string& l : arff_rows(a)) arff.push_back(l);
    for (const std::string& l : csv_rows(sc)) scen.push_back(l);
    const std::string nb = read_all(s / "features.npy");
    const Npy n = parse_npy(nb);
    ASSERT_TRUE(n.ok) << n.why;
    EXPECT_EQ(n.rows, bounds[i + 1] - bounds[i]) << "the shard's npy shape counts its own rows";
    npy_data += nb.substr(n.header_bytes);
    EXPECT_EQ(read_all(s / "features.columns.txt"), read_all(whole / "features.columns.txt"));
    json m = read_json(s / "manifest.json");
    EXPECT_EQ(m["shard"]["index"], i);
    EXPECT_EQ(m["shard"]["count"], 3);
    EXPECT_EQ(m["shard"]["begin"], bounds[i]) << m.dump(1);
    EXPECT_EQ(m["shard"]["end"], bounds[i + 1]) << m.dump(1);
    EXPECT_EQ(m["count"], bounds[i + 1] - bounds[i]);
    positive += m["classes"]["positive"].get<uint64_t>();
    negative += m["classes"]["negative"].get<uint64_t>();
    EXPECT_TRUE(has(r[i + 1].out, std::string("[") + std::to_string(bounds[i]) + std::string(", ") +
                                      std::to_string(bounds[i + 1]) + ")"))
        << describe_run(r[i + 1]);
  }
  EXPECT_TRUE(csv == csv_rows(read_all(whole / "features.csv"))) << "shard CSV rows differ from the whole run's";
  EXPECT_TRUE(arff == arff_rows(read_all(whole / "features.arff"))) << "shard ARFF rows differ from the whole run's";
  EXPECT_EQ(scen, csv_rows(read_all(whole / "scenarios.csv")));
  const std::string wb = read_all(whole / "features.npy");
  const Npy wn = parse_npy(wb);
  ASSERT_TRUE(wn.ok) << wn.why;
  EXPECT_EQ(wn.rows, 1000u);
  EXPECT_TRUE(npy_data == wb.substr(wn.header_bytes)) << "shard npy data differ from the whole run's";
  json wm = read_json(whole / "manifest.json");
  EXPECT_EQ(wm["shard"]["begin"], 0);
  EXPECT_EQ(wm["shard"]["end"], 1000);
  EXPECT_EQ(positive, wm["classes"]["positive"].get<uint64_t>());
  EXPECT_EQ(negative, wm["classes"]["negative"].get<uint64_t>());
  EXPECT_EQ(positive, 500u);
}

TEST(GenerateShards, ImageFoldersSplitByIndex) {
  GenTempDir t;
  const Args spec{"--count", "10", "--seed", "4", "--what", "both", "--format", "csv", "--annotations", "--quiet"};
  std::vector<Args> commands{gen(spec, t.w() / "whole")};
  for (int i = 0; i < 3; ++i)
    commands.push_back(
        gen(plus(spec, {"--shard", std::to_string(i) + "/3"}), t.w() / (std::string("s") + std::to_string(i))));
  const std::vector<RunResult> r = run_ps_all(t, commands);
  for (const RunResult& x : r) ExpectOk(x);
  const std::vector<std::vector<std::string>> want{{"00000000", "00000001", "00000002"},
                                                   {"00000003", "00000004", "00000005"},
                                                   {"00000006", "00000007", "00000008", "00000009"}};
  for (int i = 0; i < 3; ++i) {
    const fs::path s = t.w() / (std::string("s") + std::to_string(i));
    EXPECT_EQ(entries_of(s / "images"), want[i]) << "shard " << i;
    for (const std::string& folder : want[i]) {
      SCOPED_TRACE(std::string("shard ") + std::to_string(i) + " images/" + folder);
      ExpectSameTree(s / "images" / folder, t.w() / "whole" / "images" / folder);
    }
  }
}

// --png-level changes the PNGs' bytes, never their pixels, and is part of the run's identity.
TEST(GeneratePngLevel, ChangesTheBytesNotThePixelsAndIsPartOfTheIdentity) {
  GenTempDir t;
  const Args spec{"--count", "6", "--seed", "4", "--what", "images", "--annotations", "--quiet"};
  const std::vector<std::string> levels{"", "0", "9"};  // the default (1), stored, the smallest
  std::vector<Args> commands;
  for (size_t i = 0; i < levels.size(); ++i)
    commands.push_back(gen(levels[i].empty() ? spec : plus(spec, {"--png-level", levels[i]}),
                           t.w() / (std::string("l") + std::to_string(i))));
  for (const RunResult& r : run_ps_all(t, commands)) ExpectOk(r);
  const fs::path l1 = t.w() / "l0", l0 = t.w() / "l1", l9 = t.w() / "l2";
  const std::vector<std::string> files = files_under(l1 / "images");
  ASSERT_EQ(files.size(), 6u * 11);
  EXPECT_EQ(files_under(l0 / "images"), files);
  EXPECT_EQ(files_under(l9 / "images"), files);
  uint64_t bytes1 = 0, bytes0 = 0;
  for (const std::string& f : files) {
    SCOPED_TRACE(f);
    if (fs::path(f).extension() != ".png") {
      EXPECT_EQ(read_all(l0 / "images" / f), read_all(l1 / "images" / f));
      continue;
    }
    const portalsim::Image a = portalsim::read_image((l1 / "images" / f).string(), "default"),
                           b = portalsim::read_image((l0 / "images" / f).string(), "level 0"),
                           c = portalsim::read_image((l9 / "images" / f).string(), "level 9");
    EXPECT_TRUE(a.pixels == b.pixels && a.pixels == c.pixels && a.channels == c.channels);
    bytes1 += fs::file_size(l1 / "images" / f);
    bytes0 += fs::file_size(l0 / "images" / f);
    if (f.find("upper.png") != std::string::npos && f.find("mask") == std::string::npos) {
      EXPECT_NE(read_all(l1 / "images" / f), read_all(l9 / "images" / f));
    }
  }
  EXPECT_GT(bytes0, 2 * bytes1) << "level 0 stores, level 1 compresses";
  EXPECT_EQ(read_json(l1 / "manifest.json")["spec"]["png_level"], 1);
  EXPECT_EQ(read_json(l0 / "manifest.json")["spec"]["png_level"], 0);
  EXPECT_EQ(read_json(l9 / "manifest.json")["spec"]["png_level"], 9);
  // A finished run at level 1 is not "complete" for a command asking level 9.
  const RunResult r = run_ps(t, gen(plus(spec, {"--png-level", "9", "--resume"}), l1));
  EXPECT_TRUE(r.exited && r.status != 0) << describe_run(r);
  EXPECT_TRUE(has(r.err, "png_level")) << describe_run(r);
}

// ---------------------------------------------------------------------------------------------
// 5. Interrupting and resuming.

// A features run that takes a couple of seconds (small batches: a checkpoint every 8 scenarios).
// The uninterrupted reference runs use larger batches: the batch size is not part of the spec
// and must not change a byte.
const Args kLongSpec{"--count", "30000",    "--seed",  "21",      "--rule", "gun",    "--block",
                     "40",      "--format", "csv,npy", "--batch", "8",      "--quiet"};

void ExpectInterruptedState(const fs::path& dir, const std::vector<std::string>& data_files) {
  std::error_code ec;
  EXPECT_FALSE(fs::exists(dir / "manifest.json", ec)) << "no manifest before the run is complete";
  EXPECT_TRUE(fs::exists(dir / ".portalsim" / "checkpoint.json", ec)) << "the checkpoint must be kept";
  for (const std::string& f : data_files) {
    EXPECT_FALSE(fs::exists(dir / f, ec)) << f << " must not have its final name before the run is complete";
    EXPECT_TRUE(fs::exists(dir / (f + ".partial"), ec)) << f << ".partial must exist";
  }
}

TEST(GenerateResume, KillNineThenResumeMatchesAnUninterruptedRun) {
  GenTempDir t;
  const fs::path dir = t.w() / "killed", ref = t.w() / "ref";
  const Started reference = start_ps(t, gen(with(kLongSpec, "--batch", "1000"), ref));
  const Started victim = start_ps(t, gen(kLongSpec, dir));
  const portalsim::test::Killed killed = portalsim::test::kill_mid_run(victim, dir, 1, 300);
  const RunResult& k = killed.result;
  ExpectOk(wait_for(reference));
  ASSERT_TRUE(k.signaled && k.signal == SIGKILL) << "the run ended before it could be killed; make kLongSpec longer\n"
                                                 << describe_run(k);
  ASSERT_TRUE(killed.next > 0 && killed.next < 30000) << "the kill must come mid-run: next " << killed.next;
  EXPECT_EQ(checkpoint_next(dir), killed.next) << "the checkpoint is the one the kill left";
  ExpectInterruptedState(dir, {"features.csv", "features.npy", "scenarios.csv"});

  // Resume with other batch and thread counts: they are not part of the spec.
  const RunResult r =
      run_ps(t, gen(plus(with(with(kLongSpec, "--batch", "1000"), "--threads", "1"), {"--resume"}), dir));
  ExpectOk(r);
  ExpectSameTree(dir, ref);
  EXPECT_FALSE(fs::exists(dir / ".portalsim")) << "the checkpoint folder goes once the run is complete";

  // A complete folder: --resume has nothing to do, says so, and changes nothing.
  const auto before = files_under(dir);
  const std::string manifest = read_all(dir / "manifest.json");
  const RunResult again = run_ps(t, gen(plus(kLongSpec, {"--resume"}), dir));
  ExpectOk(again);
  EXPECT_TRUE(has(again.out + again.err, "already complete")) << describe_run(again);
  EXPECT_EQ(files_under(dir), before);
  EXPECT_EQ(read_all(dir / "manifest.json"), manifest);
}

// SIGINT (Ctrl-C) and SIGTERM: the batch in hand is finished, checkpointed, exit 130.
void ExpectSignalStopsConsistentlyAndResumes(int sig) {
  GenTempDir t;
  const fs::path dir = t.w() / "stopped", ref = t.w() / "ref";
  const Started reference = start_ps(t, gen(with(kLongSpec, "--batch", "1000"), ref));
  const Started victim = start_ps(t, gen(kLongSpec, dir));
  const bool progressed = wait_for_checkpoint(victim, dir, 1);
  send_signal(victim, sig);
  const RunResult k = wait_for(victim);
  ExpectOk(wait_for(reference));
  ASSERT_TRUE(progressed) << describe_run(k);
  SCOPED_TRACE(describe_run(k));
  ASSERT_FALSE(k.signaled) << strsignal(sig) << " must stop the run cleanly, not kill it";
  EXPECT_TRUE(k.exited);
  EXPECT_EQ(k.status, 130) << "an interrupted run exits with 130";
  EXPECT_TRUE(has(k.err, "--resume")) << "the message must say how to continue";
  EXPECT_EQ(stderr_messages(k.err).size(), 1u);
  // The summary line must not read as a finished run's: it says it was interrupted and how
  // to finish (issue 36).
  EXPECT_TRUE(has(k.out, "interrupted after ")) << "the summary must say the run was interrupted";
  EXPECT_TRUE(has(k.out, "--resume")) << "the summary must say how to finish the run";
  const long long next = checkpoint_next(dir);
  EXPECT_GT(next, 0);
  EXPECT_LT(next, 30000);
  ExpectInterruptedState(dir, {"features.csv", "features.npy", "scenarios.csv"});
  // What is there is consistent: the partial CSV holds exactly the checkpointed rows.
  EXPECT_EQ(static_cast<long long>(csv_rows(read_all(dir / "features.csv.partial")).size()), next);
  EXPECT_EQ(static_cast<long long>(csv_rows(read_all(dir / "scenarios.csv.partial")).size()), next);

  const RunResult r = run_ps(t, gen(plus(with(kLongSpec, "--batch", "1000"), {"--resume"}), dir));
  ExpectOk(r);
  ExpectSameTree(dir, ref);
}

TEST(GenerateResume, CtrlCStopsConsistentlyAndResumes) { ExpectSignalStopsConsistentlyAndResumes(SIGINT); }

TEST(GenerateResume, SigtermStopsConsistentlyAndResumes) { ExpectSignalStopsConsistentlyAndResumes(SIGTERM); }

TEST(GenerateResume, ImagesKillNineThenResumeMatchesAnUninterruptedRun) {
  GenTempDir t;
  const Args spec{"--count", "160",      "--seed", "9",       "--what", "both",   "--rule",
                  "gun",     "--format", "csv",    "--batch", "2",      "--quiet"};
  const fs::path dir = t.w() / "killed", ref = t.w() / "ref";
  const Started reference = start_ps(t, gen(with(spec, "--batch", "50"), ref));
  const Started victim = start_ps(t, gen(spec, dir));
  const portalsim::test::Killed killed = portalsim::test::kill_mid_run(victim, dir, 1, 300);
  const RunResult& k = killed.result;
  ExpectOk(wait_for(reference));
  ASSERT_TRUE(k.signaled) << "the run ended before it could be killed\n" << describe_run(k);
  ASSERT_TRUE(killed.next > 0 && killed.next < 160) << "the kill must come mid-run: next " << killed.next;
  ExpectInterruptedState(dir, {"features.csv", "scenarios.csv"});
  const RunResult r = run_ps(t, gen(plus(spec, {"--resume"}), dir));
  ExpectOk(r);
  ExpectSameTree(dir, ref);
  EXPECT_EQ(entries_of(dir / "images").size(), 160u) << "no staging folders may be left";
}

// Makes DIR an interrupted run: starts kLongSpec and stops it with SIGINT as soon as its
// checkpoint exists.
void make_interrupted(const GenTempDir& t, const fs::path& dir) {
  const Started s = start_ps(t, gen(kLongSpec, dir));
  // At least one batch written, so the interrupted folder holds data, not only a checkpoint.
  const bool progressed = wait_for_checkpoint(s, dir, 1);
  send_signal(s, SIGINT);
  const RunResult r = wait_for(s);
  ASSERT_TRUE(progressed) << "the run never checkpointed a batch\n" << describe_run(r);
  ASSERT_TRUE(r.exited && r.status == 130) << describe_run(r);
}

TEST(GenerateResume, DifferentSpecIsRefusedNamingWhatDiffers) {
  GenTempDir t;
  const fs::path dir = t.w() / "run";
  ASSERT_NO_FATAL_FAILURE(make_interrupted(t, dir));
  const auto before = snapshot(dir);
  ASSERT_FALSE(before.empty());
  struct Case {
    std::string option, value, names;
  };
  const std::vector<Case> cases{
      {"--seed", "22", "seed"}, {"--count", "30001", "count"}, {"--block", "20", "block"}, {"--shard", "1/2", "shard"}};
  for (const Case& c : cases) {
    const RunResult r = run_ps(t, gen(plus(with(kLongSpec, c.option, c.value), {"--resume"}), dir));
    SCOPED_TRACE(describe_run(r));
    EXPECT_TRUE(r.exited && r.status != 0) << "resuming with a different spec must be refused";
    EXPECT_EQ(stderr_messages(r.err).size(), 1u);
    EXPECT_TRUE(has(r.err, "--resume"));
    EXPECT_TRUE(has(r.err, c.names)) << "the message must name what differs: " << c.names;
    EXPECT_TRUE(snapshot(dir) == before) << "a refused resume must leave the folder as it was";
  }
  // The folder is still good for the right spec.
  ExpectOk(run_ps(t, gen(plus(with(kLongSpec, "--batch", "1000"), {"--resume"}), dir)));
  EXPECT_TRUE(fs::exists(dir / "manifest.json"));
}

// A crash while a finished run renames its files into place (AppendFile::finish fsyncs each
// file first, which can take seconds for a large table) leaves some final names, some .partial
// files and the checkpoint. This builds exactly that state from a complete run: the checkpoint
// the last batch wrote (next = end, every file's full size and hash), features.npy not yet
// renamed, no manifest. --resume must finish the job.
TEST(GenerateResume, CrashWhileFinishingIsResumable) {
  GenTempDir t;
  const Args spec{"--count", "50", "--seed", "6", "--format", "csv,npy", "--quiet"};
  const fs::path ref = t.w() / "ref", dir = t.w() / "crashed", late = t.w() / "late";
  ExpectOk(run_ps(t, gen(spec, ref)));
  json m = read_json(ref / "manifest.json");
  ASSERT_TRUE(m.contains("outputs") && m.contains("classes")) << m.dump(1);
  json checkpoint;
  checkpoint["identity"] = {
      {"portalsim", m["portalsim"]}, {"catalogue", m["catalogue"]}, {"spec", m["spec"]}, {"shard", m["shard"]}};
  checkpoint["next"] = m["shard"]["end"];
  checkpoint["positive"] = m["classes"]["positive"];
  checkpoint["negative"] = m["classes"]["negative"];
  checkpoint["files"] = json::array();
  for (const json& o : m["outputs"])
    checkpoint["files"].push_back({{"name", o["name"]},
                                   {"bytes", o["bytes"]},
                                   {"xxh3", std::stoull(o["xxh3_64"].get<std::string>(), nullptr, 16)}});
  for (const fs::path& d : {dir, late}) {
    fs::copy(ref, d, fs::copy_options::recursive);
    fs::create_directory(d / ".portalsim");
    write_all(d / ".portalsim" / "checkpoint.json", checkpoint.dump(1) + "\n");
  }
  // Crashed between renaming scenarios.csv and features.csv and renaming features.npy.
  fs::rename(dir / "features.npy", dir / "features.npy.partial");
  fs::remove(dir / "manifest.json");
  // Crashed after writing the manifest, before removing the checkpoint.
  for (const fs::path& d : {dir, late}) {
    SCOPED_TRACE(d.filename().string());
    const RunResult r = run_ps(t, gen(plus(spec, {"--resume"}), d));
    ExpectOk(r);
    fs::remove_all(d / ".portalsim");  // compare the data, whatever became of the checkpoint
    ExpectSameTree(d, ref);
  }
}

TEST(GenerateResume, ResumeIntoAFolderWithoutACheckpointSaysSo) {
  GenTempDir t;
  const fs::path dir = t.w() / "notes";
  fs::create_directory(dir);
  write_all(dir / "notes.txt", "mine\n");
  const RunResult r = run_ps(t, gen({"--count", "5", "--resume", "--quiet"}, dir));
  SCOPED_TRACE(describe_run(r));
  EXPECT_TRUE(r.exited && r.status != 0);
  EXPECT_EQ(stderr_messages(r.err).size(), 1u);
  EXPECT_TRUE(has(r.err, dir.string()));
  EXPECT_FALSE(has(r.err, "use --resume")) << "--resume was given; telling the user to use it does not help";
  EXPECT_EQ(entries_of(dir), std::vector<std::string>{"notes.txt"});
  EXPECT_EQ(read_all(dir / "notes.txt"), "mine\n");
}

// A finished folder whose manifest.json is damaged (valid JSON of the wrong shape, as the
// manifest fuzz target first found, or a field of the wrong type): --resume refuses it
// naming the file and the field, exit 4, and changes nothing.
TEST(GenerateResume, DamagedManifestIsRefusedNamingIt) {
  GenTempDir t;
  const fs::path dir = t.w() / "done";
  const Args spec{"--count", "5", "--quiet"};
  ExpectOk(run_ps(t, gen(spec, dir)));
  const std::string good = read_all(dir / "manifest.json");
  json wrong_count = json::parse(good);
  wrong_count["count"] = "5";
  for (const auto& [text, field] : std::vector<std::pair<std::string, std::string>>{
           {"[]", "expected a JSON object"}, {"1", "expected a JSON object"}, {wrong_count.dump(), "count"}}) {
    SCOPED_TRACE(text.substr(0, 40));
    write_all(dir / "manifest.json", text);
    const auto before = snapshot(dir);
    const RunResult r = run_ps(t, gen(plus(spec, {"--resume"}), dir));
    SCOPED_TRACE(describe_run(r));
    EXPECT_TRUE(r.exited && r.status == 4) << "a damaged run folder is an output problem";
    EXPECT_EQ(stderr_messages(r.err).size(), 1u);
    EXPECT_TRUE(has(r.err, (dir / "manifest.json").string()));
    EXPECT_TRUE(has(r.err, field));
    EXPECT_TRUE(snapshot(dir) == before);
  }
}

// ---------------------------------------------------------------------------------------------
// 6. Refusals: the output folder.

TEST(GenerateOutput, NonEmptyFolderIsRefused) {
  GenTempDir t;
  const fs::path mine = t.w() / "mine", done = t.w() / "done";
  fs::create_directory(mine);
  write_all(mine / "notes.txt", "keep me\n");
  ExpectOk(run_ps(t, gen({"--count", "5", "--quiet"}, done)));
  for (const fs::path& d : {mine, done}) {
    const auto before = snapshot(d);
    const RunResult r = run_ps(t, gen({"--count", "5", "--quiet"}, d));
    SCOPED_TRACE(describe_run(r));
    EXPECT_TRUE(r.exited && r.status != 0);
    EXPECT_EQ(stderr_messages(r.err).size(), 1u);
    EXPECT_TRUE(has(r.err, d.string()));
    EXPECT_TRUE(has(r.err, "not empty"));
    EXPECT_TRUE(has(r.err, "--resume"));
    EXPECT_EQ(r.out, "");
    EXPECT_TRUE(snapshot(d) == before) << d << " must be left untouched";
  }
  // An existing empty folder is fine.
  const fs::path empty = t.w() / "empty";
  fs::create_directory(empty);
  ExpectOk(run_ps(t, gen({"--count", "5", "--quiet"}, empty)));
  EXPECT_TRUE(fs::exists(empty / "manifest.json"));
}

TEST(GenerateOutput, OutIsARegularFile) {
  GenTempDir t;
  const fs::path file = t.w() / "afile";
  write_all(file, "keep me\n");
  const RunResult r = run_ps(t, gen({"--count", "5", "--quiet"}, file));
  SCOPED_TRACE(describe_run(r));
  EXPECT_TRUE(r.exited && r.status != 0);
  EXPECT_EQ(stderr_messages(r.err).size(), 1u);
  EXPECT_TRUE(has(r.err, file.string()));
  EXPECT_EQ(read_all(file), "keep me\n");
  EXPECT_EQ(entries_of(t.w()), std::vector<std::string>{"afile"});
}

TEST(GenerateOutput, UnwritableLocationUnderARegularFile) {
  GenTempDir t;
  const fs::path file = t.w() / "afile";
  write_all(file, "keep me\n");
  const fs::path out = file / "sub" / "out";
  const RunResult r = run_ps(t, gen({"--count", "5", "--quiet"}, out));
  ExpectRefused(r, out, false, {out.string()});
  EXPECT_EQ(read_all(file), "keep me\n");
  EXPECT_EQ(entries_of(t.w()), std::vector<std::string>{"afile"});
}

// ---------------------------------------------------------------------------------------------
// 7. Bad specs.

std::string at_line(const fs::path& file, int line) {
  return file.string() + std::string(":") + std::to_string(line) + ":";
}

// A file that must be refused: its text, the line the message names, and what else it names.
struct FileCase {
  std::string text;
  int line;
  std::vector<std::string> more;
};

// Each case written into t as NAME<i>.EXT and given to generate as `flag`: a command that must
// be refused naming its file and line; the first also with OUT existing (empty) where
// `first_existing`.
std::vector<Refusal> file_refusals(const GenTempDir& t, const std::string& flag, const std::string& name,
                                   const std::string& ext, const std::vector<FileCase>& files, bool first_existing) {
  std::vector<Refusal> cases;
  for (size_t i = 0; i < files.size(); ++i) {
    const fs::path p = t.w() / (name + std::to_string(i) + ext);
    write_all(p, files[i].text);
    std::vector<std::string> needles{at_line(p, files[i].line)};
    needles.insert(needles.end(), files[i].more.begin(), files[i].more.end());
    cases.push_back({{flag, p.string(), "--quiet"}, needles, first_existing && i == 0});
  }
  return cases;
}

TEST(GenerateBadSpec, SpecFileErrorsNameFileLineAndKey) {
  GenTempDir t;
  const std::vector<FileCase> specs{
      {"count = 10\nseed = [1\n", 2, {"syntax"}},
      {"count = 10\ncolour = \"red\"\n", 2, {"colour", "unknown key"}},
      {"seed = 1\ncount = -5\n", 2, {"count", "-5"}},
      {"count = \"x\"\n", 1, {"count"}},
      {"count = 10\n\npixel_noise = nan\n", 3, {"pixel_noise"}},
      {"count = 10\nobjects = \"5..2\"\n", 2, {"objects", "5..2"}},
  };
  std::vector<Refusal> cases = file_refusals(t, "--spec", "spec", ".toml", specs, true);
  cases.push_back({{"--spec", (t.w() / "missing.toml").string()}, {(t.w() / "missing.toml").string()}});
  ExpectAllRefused(t, cases);
}

TEST(GenerateBadSpec, OptionErrorsNameTheOption) {
  GenTempDir t;
  ExpectAllRefused(
      t,
      {
          {{"--count", "5", "--objects", "3..20"}, {"--objects", "3..20"}, true},
          {{"--count", "5", "--pool", "gun,laser"}, {"pool", "\"laser\""}},
          {{"--count", "5", "--balance"}, {"balance", "--rule"}},
          {{"--count", "5", "--balance", "--rule", "gun", "--pool", "iron-rod,metal-plate"}, {"balance", "gun"}, true},
          {{"--count", "5", "--format", "xls"}, {"format", "xls"}},
          {{"--count", "5", "--what", "pictures"}, {"what", "pictures"}},
          {{"--count", "5", "--shard", "3/3"}, {"--shard", "3/3"}},
          {{"--count", "5", "--shard", "x"}, {"--shard", "\"x\""}},
          {{"--count", "5", "--subjects", "0"}, {"subjects", "0"}},
          {{"--count", "0"}, {"count"}},
          {{"--count", "5", "--rule", "gun|laser"}, {"rule", "laser"}},
          {{"--count", "5", "--what", "images", "--png-level", "10"}, {"--png-level", "\"10\"", "between 0 and 9"}},
          {{"--count", "5", "--what", "images", "--png-level", "x"}, {"--png-level", "\"x\""}},
          {{"--count", "5", "--png-level", "3"}, {"--png-level", "image folders"}},
          {{"--count", "5", "--what", "images", "--format", "h5", "--png-level", "0"},
           {"--png-level", "image folders"}},
      });
}

// Values that are only checked after the spec file is read (the object pool, what, format,
// subjects) must still point at the spec file's line, as the other spec errors do.
TEST(GenerateBadSpec, SpecValuesCheckedLaterStillNameFileAndLine) {
  GenTempDir t;
  const std::vector<FileCase> specs{
      {"count = 10\npool = [\"gun\", \"laser\"]\n", 2, {"pool", "laser"}},
      {"count = 10\nwhat = \"pictures\"\n", 2, {"what", "pictures"}},
      {"count = 10\nformat = \"xls\"\n", 2, {"format", "xls"}},
      {"count = 10\nsubjects = [9]\n", 2, {"subjects", "9"}},
      {"count = 10\nwhat = \"images\"\npng_level = 12\n", 3, {"png_level", "12"}},
      {"count = 10\npng_level = 3\n", 2, {"png_level", "image folders"}},
  };
  ExpectAllRefused(t, file_refusals(t, "--spec", "spec", ".toml", specs, false));
}

const char* kScenarioHeader =
    "subject,region1,region2,region3,region4,region5,region6,region7,region8,region9,region10,region11,region12,"
    "region13,label\n";
const char* kGunRow = "1,gun,none,none,none,none,none,none,none,none,none,none,none,none,yes\n";

TEST(GenerateBadSpec, ScenarioFileErrorsNameFileLineAndColumn) {
  GenTempDir t;
  const std::vector<FileCase> lists{
      {std::string(kScenarioHeader) + kGunRow +
           "2,none,laser,none,none,none,none,none,none,none,none,none,none,none,no\n",
       3,
       {"region2", "laser"}},
      {"subject,region1,region2,region3,region4,region5,region6,region7,region8,region9,region10,region11,region12,"
       "label\n" +
           std::string(kGunRow),
       1,
       {"region13"}},
      {std::string(kScenarioHeader) + kGunRow + "2,none,none,none,none,none,none,none,none,none,none,none,none,no\n",
       3,
       {"15", "14"}},
      {std::string(kScenarioHeader) + kGunRow +
           "9,none,none,none,none,none,none,none,none,none,none,none,none,none,no\n",
       3,
       {"subject", "9"}},
  };
  ExpectAllRefused(t, file_refusals(t, "--scenarios", "list", ".csv", lists, true));

  // The well-formed list runs, one row per scenario, the labels as given.
  const fs::path good = t.w() / "good.csv";
  write_all(good, std::string(kScenarioHeader) + kGunRow +
                      "2,none,rod:v,none,none,none,none,none,none,none,none,none,none,plate,no\n");
  const fs::path out = t.w() / "good-out";
  ExpectOk(run_ps(t, gen({"--scenarios", good.string(), "--format", "csv", "--quiet"}, out)));
  const std::vector<std::string> sc = csv_rows(read_all(out / "scenarios.csv"));
  ASSERT_EQ(sc.size(), 2u);
  EXPECT_EQ(sc[0], "0,1,gun:h,none,none,none,none,none,none,none,none,none,none,none,none,yes");
  EXPECT_EQ(sc[1], "1,2,none,iron-rod:v,none,none,none,none,none,none,none,none,none,none,metal-plate,no");
}

// A list is read as a stream: one over the 64 MiB that catalogues and specs may hold (here
// made long by comment lines between its rows) runs, its rows as given.
TEST(GenerateLists, AListOver64MiBRuns) {
  GenTempDir t;
  const fs::path big = t.w() / "big.csv";
  {
    std::ofstream o(big, std::ios::binary);
    o << kScenarioHeader;
    const std::string comment = "#" + std::string(60000, 'c') + "\n";
    for (int i = 0; i < 1150; ++i) {
      o << comment;
      if (i % 100 == 0)
        o << (i % 200 ? kGunRow : "2,none,rod:v,none,none,none,none,none,none,none,none,none,none,none,no\n");
    }
  }
  ASSERT_GT(fs::file_size(big), 64ull << 20);
  const fs::path out = t.w() / "big-out";
  ExpectOk(run_ps(t, gen({"--scenarios", big.string(), "--format", "csv", "--batch", "5", "--quiet"}, out)));
  const std::vector<std::string> sc = csv_rows(read_all(out / "scenarios.csv"));
  ASSERT_EQ(sc.size(), 12u);
  EXPECT_EQ(sc[1], "1,1,gun:h,none,none,none,none,none,none,none,none,none,none,none,none,yes");
  EXPECT_EQ(sc[2], "2,2,none,iron-rod:v,none,none,none,none,none,none,none,none,none,none,none,no");
}

// The rows of a long list (no two stretches of it alike), with a row far down it bad.
std::string long_list(int rows, int bad_row) {
  std::string text = kScenarioHeader;
  const char* objects[] = {"gun", "none", "rod:v", "belt-buckle", "none", "pendant"};
  for (int i = 0; i < rows; ++i) {
    const uint32_t h = static_cast<uint32_t>(i) * 2654435761u;  // rows that never repeat in step
    text += std::to_string(1 + (h >> 28) % 4);
    for (int r = 0; r < 13; ++r) text += std::string(",") + objects[(h >> (r * 2)) % 6];
    text += i == bad_row ? ",maybe\n" : (i % 3 ? ",no\n" : ",yes\n");
  }
  return text;
}

// With --shard, each shard's rows (read from the list past the others') are the whole run's.
TEST(GenerateLists, ShardsOfAListConcatenateToTheWholeRun) {
  GenTempDir t;
  const fs::path list = t.w() / "list.csv";
  write_all(list, long_list(500, -1));
  const Args spec{"--scenarios", list.string(), "--format", "csv", "--batch", "64", "--quiet"};
  std::vector<Args> commands{gen(spec, t.w() / "whole")};
  for (int i = 0; i < 3; ++i)
    commands.push_back(gen(plus(spec, {"--shard", std::to_string(i) + "/3"}), t.w() / ("s" + std::to_string(i))));
  const std::vector<RunResult> r = run_ps_all(t, commands);
  for (const RunResult& x : r) ExpectOk(x);
  std::vector<std::string> csv, scen;
  for (int i = 0; i < 3; ++i) {
    const fs::path s = t.w() / ("s" + std::to_string(i));
    for (const std::string& l : csv_rows(read_all(s / "features.csv"))) csv.push_back(l);
    for (const std::string& l : csv_rows(read_all(s / "scenarios.csv"))) scen.push_back(l);
  }
  EXPECT_EQ(scen.size(), 500u);
  EXPECT_TRUE(scen == csv_rows(read_all(t.w() / "whole" / "scenarios.csv")));
  EXPECT_TRUE(csv == csv_rows(read_all(t.w() / "whole" / "features.csv")));
}

// A bad row far down a long list fails the run with its line before anything is written:
// no half-written folder, whichever batch it would have come in.
TEST(GenerateLists, ABadRowLateInALongListFailsBeforeAnyOutput) {
  GenTempDir t;
  const fs::path list = t.w() / "late.csv";
  write_all(list, long_list(20000, 19990));
  ExpectAllRefused(t, {{{"--scenarios", list.string(), "--format", "csv,npy", "--batch", "1000", "--quiet"},
                        {at_line(list, 19992), "label", "maybe"},
                        true}});
}

// A list-driven run killed mid-run resumes to the files of an uninterrupted one.
TEST(GenerateLists, KillNineThenResumeMatchesAnUninterruptedRun) {
  GenTempDir t;
  const fs::path list = t.w() / "list.csv";
  write_all(list, long_list(30000, -1));
  const Args spec{"--scenarios", list.string(), "--block", "40", "--format", "csv,npy", "--batch", "8", "--quiet"};
  const fs::path dir = t.w() / "killed", ref = t.w() / "ref";
  const Started reference = start_ps(t, gen(with(spec, "--batch", "1000"), ref));
  const Started victim = start_ps(t, gen(spec, dir));
  const portalsim::test::Killed killed = portalsim::test::kill_mid_run(victim, dir, 1, 300);
  ExpectOk(wait_for(reference));
  ASSERT_TRUE(killed.result.signaled) << "the run ended before it could be killed\n" << describe_run(killed.result);
  ASSERT_TRUE(killed.next > 0 && killed.next < 30000) << "the kill must come mid-run: next " << killed.next;
  ExpectOk(run_ps(t, gen(plus(with(spec, "--batch", "1000"), {"--resume"}), dir)));
  ExpectSameTree(dir, ref);
}

// A balanced rule that the up-front check finds possible but that is too rare to draw for an
// index: the run fails when it reaches that index. The failure must leave no half-written
// data set behind (the folder was new), or the next attempt is refused as "not empty".
TEST(GenerateBadSpec, TooRareBalancedRuleLeavesNoHalfWrittenFolder) {
  GenTempDir t;
  const fs::path out = t.w() / "rare";
  const RunResult r =
      run_ps(t, gen({"--count", "10", "--seed", "1", "--balance", "--rule",
                     "gun:h&gun:v&iron-rod:h&iron-rod:v&pendant&belt-buckle", "--objects", "6..6", "--quiet"},
                    out));
  ASSERT_FALSE(r.exited && r.status == 0) << "seed 1 draws this rule after all; pick a rarer rule";
  ExpectRefused(r, out, false, {"balance"});
}

// ---------------------------------------------------------------------------------------------
// 8. `portalsim features` gives the same rows as generate.

TEST(FeaturesCmd, RowsEqualGenerate) {
  GenTempDir t;
  const fs::path g = t.w() / "gen";
  ExpectOk(run_ps(t, gen({"--count", "120", "--seed", "12", "--what", "both", "--format", "csv,arff,npy", "--rule",
                          "gun", "--quiet"},
                         g)));
  const fs::path x = t.w() / "x";
  fs::create_directory(x);
  const std::vector<RunResult> r =
      run_ps_all(t, {{"features", (g / "images").string(), "--out", (x / "X.csv").string()},
                     {"features", (g / "images").string(), "--out", (x / "X.arff").string()},
                     {"features", (g / "images").string(), "--out", (x / "X.npy").string()}});
  for (const RunResult& y : r) ExpectOk(y);
  EXPECT_TRUE(has(r[0].out, "120 rows")) << describe_run(r[0]);
  const std::string gcsv = read_all(g / "features.csv");
  const std::vector<std::string> rows = csv_rows(gcsv);
  ASSERT_EQ(rows.size(), 120u);
  EXPECT_EQ(lines_of(read_all(x / "X.csv")).at(0), lines_of(gcsv).at(0)) << "the CSV headers differ";
  EXPECT_TRUE(csv_rows(read_all(x / "X.csv")) == rows) << "features X.csv rows differ from generate's";
  EXPECT_TRUE(arff_rows(read_all(x / "X.arff")) == arff_rows(read_all(g / "features.arff")))
      << "features X.arff rows differ from generate's";
  EXPECT_TRUE(read_all(x / "X.npy") == read_all(g / "features.npy")) << "features X.npy differs from generate's";
  EXPECT_EQ(read_all(x / "X.columns.txt"), read_all(g / "features.columns.txt"));
  EXPECT_EQ(entries_of(x), (std::vector<std::string>{"X.arff", "X.columns.txt", "X.csv", "X.npy"}));
  // Labels: scenarios.csv's yes/no, each folder's threat.txt and the table's class agree.
  const std::vector<std::string> sc = csv_rows(read_all(g / "scenarios.csv"));
  ASSERT_EQ(sc.size(), 120u);
  int positives = 0;
  for (size_t i = 0; i < 120; ++i) {
    const bool yes = sc[i].size() > 4 && sc[i].compare(sc[i].size() - 4, 4, ",yes") == 0;
    positives += yes;
    const std::string cls = rows[i].substr(rows[i].rfind(',') + 1);
    EXPECT_EQ(cls, yes ? "positive" : "negative") << "row " << i;
    char name[16];
    std::snprintf(name, sizeof name, "%08zu", i);
    EXPECT_EQ(read_all(g / "images" / name / "threat.txt"), yes ? "yes\n" : "no\n") << name;
  }
  EXPECT_GT(positives, 0);
}

TEST(FeaturesCmd, SimulateFolderGivesItsOwnRow) {
  GenTempDir t;
  const fs::path sim = t.w() / "sim", out = t.w() / "row.csv";
  ExpectOk(
      run_ps(t, {"simulate", "gun", "rod:v", "none", "plate", "--seed", "3", "--rule", "gun", "--out", sim.string()}));
  ExpectOk(run_ps(t, {"features", sim.string(), "--out", out.string()}));
  EXPECT_EQ(read_all(out), read_all(sim / "features.csv"));
  EXPECT_EQ(csv_rows(read_all(out)).size(), 1u);
}

TEST(FeaturesCmd, BadInput) {
  GenTempDir t;
  const fs::path sim = t.w() / "sim";
  ExpectOk(run_ps(t, {"simulate", "gun", "--out", sim.string()}));
  const fs::path empty = t.w() / "empty", bad = t.w() / "bad", outs = t.w() / "outs";
  fs::create_directory(empty);
  fs::create_directory(empty / "sub");
  write_all(empty / "sub" / "metal.txt", "200\n");
  fs::create_directory(bad);
  fs::copy(sim, bad / "a", fs::copy_options::recursive);
  fs::copy(sim, bad / "b", fs::copy_options::recursive);
  write_all(bad / "b" / "metal.txt", "200,200,200,200,200,200,200,200,200,200,200,200,200,200,200,200,200,200\n");
  fs::create_directory(outs);
  write_all(outs / "taken.csv", "keep me\n");
  const std::vector<RunResult> r = run_ps_all(t, {{"features", empty.string(), "--out", (outs / "e.csv").string()},
                                                  {"features", bad.string(), "--out", (outs / "m.csv").string()},
                                                  {"features", bad.string(), "--out", (outs / "m.npy").string()},
                                                  {"features", sim.string(), "--out", (outs / "taken.csv").string()}});
  const auto one_message = [](const RunResult& x, const std::vector<std::string>& needles) {
    SCOPED_TRACE(describe_run(x));
    EXPECT_TRUE(x.exited && x.status != 0);
    EXPECT_FALSE(x.signaled);
    EXPECT_EQ(stderr_messages(x.err).size(), 1u);
    for (const std::string& n : needles) EXPECT_TRUE(has(x.err, n)) << "stderr does not name \"" << n << "\"";
  };
  one_message(r[0], {empty.string(), "no scenario folders"});
  one_message(r[1], {(bad / "b" / "metal.txt").string() + ":1", "19"});
  one_message(r[2], {(bad / "b" / "metal.txt").string() + ":1", "19"});
  one_message(r[3], {(outs / "taken.csv").string(), "exists"});
  EXPECT_EQ(read_all(outs / "taken.csv"), "keep me\n");
  EXPECT_EQ(entries_of(outs), std::vector<std::string>{"taken.csv"}) << "no output, partial or columns file is left";
}

// ---------------------------------------------------------------------------------------------
// 9. The thesis's experimental cases.

fs::path case_spec(const std::string& name) { return fs::path(PORTALSIM_SOURCE_DIR) / "scenarios" / name; }

// 200 scenarios of scenarios/NAME into t, balanced; their scenarios.csv rows.
void generate_thesis_case(const GenTempDir& t, const std::string& name, std::vector<std::string>& rows) {
  const fs::path spec = case_spec(name);
  ASSERT_TRUE(fs::exists(spec)) << spec << " is missing";
  const fs::path out = t.w() / spec.stem();
  ExpectOk(run_ps(t, gen({"--spec", spec.string(), "--count", "200", "--quiet"}, out)));
  json m = read_json(out / "manifest.json");
  EXPECT_EQ(m["count"], 200);
  EXPECT_EQ(m["classes"]["positive"], m["classes"]["negative"]) << m.dump(1);
  rows = csv_rows(read_all(out / "scenarios.csv"));
}

TEST(GenerateThesisCases, Case1GunIsBalanced) {
  GenTempDir t;
  std::vector<std::string> sc;
  ASSERT_NO_FATAL_FAILURE(generate_thesis_case(t, "case1-gun.toml", sc));
  ASSERT_EQ(sc.size(), 200u);
  for (const std::string& row : sc) {
    const bool gun = has(row, ",gun");
    EXPECT_EQ(row.substr(row.rfind(',') + 1), gun ? "yes" : "no") << row;
  }
}

TEST(GenerateThesisCases, Case2RodAndPlateUsesItsPoolAndIsBalanced) {
  GenTempDir t;
  std::vector<std::string> sc;
  ASSERT_NO_FATAL_FAILURE(generate_thesis_case(t, "case2-rod-plate.toml", sc));
  const std::set<std::string> allowed{"metal-plate", "iron-rod:h",    "iron-rod:v",   "iron-rod", "compact-disk",
                                      "cement-tile", "ceramic-plate", "mobile-phone", "none"};
  ASSERT_EQ(sc.size(), 200u);
  int positives = 0;
  for (const std::string& row : sc) {
    const std::vector<std::string> f = split_on(row, ',');
    ASSERT_EQ(f.size(), 16u) << row;
    bool rod = false, plate = false;
    for (int k = 2; k < 15; ++k) {
      EXPECT_TRUE(allowed.count(f[k])) << "object \"" << f[k] << "\" is not in case 2's set: " << row;
      rod = rod || f[k].rfind("iron-rod", 0) == 0;
      plate = plate || f[k] == "metal-plate";
    }
    if (f[15] == "yes") {
      ++positives;
      EXPECT_TRUE(rod && plate) << "a positive must hold both an iron rod and a metal plate: " << row;
    } else {
      EXPECT_EQ(f[15], "no") << row;
      EXPECT_FALSE(rod && plate) << "a negative must not hold both: " << row;
    }
  }
  EXPECT_EQ(positives, 100);
}

}  // namespace
