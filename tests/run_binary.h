// Running the real portalsim binary from a test: stdin from /dev/null, stdout and
// stderr captured in files, the exit status read back. Shared by the suites that test
// the command line as a user meets it.
#pragma once
#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "build_config.h"

extern char** environ;

namespace portalsim::test {

// Polls `done` every poll_ms until it holds (true) or `limit_s` (scaled) passed (false).
template <class Done>
bool wait_until(Done done, int limit_s, int poll_ms = 2) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(limit_s * kTimeScale);
  for (;;) {
    if (done()) return true;
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(poll_ms));
  }
}

// A new folder named `prefix` and six random characters under $TMPDIR, else /tmp, as
// Python's tempfile and mktemp choose (the Python suites and the scripts' folders).
inline std::filesystem::path make_temp_dir(const std::string& prefix) {
  const char* dir = std::getenv("TMPDIR");
  std::string tmpl = std::string(dir && *dir ? dir : "/tmp") + "/" + prefix + "-XXXXXX";
  if (!::mkdtemp(tmpl.data())) throw std::runtime_error("mkdtemp " + tmpl + ": " + std::strerror(errno));
  return tmpl;
}

// A fresh folder (make_temp_dir) for one test: w/ is the test's workspace, cap/ holds the
// captured stdout and stderr of every run (kept apart so that w/ shows only what portalsim wrote).
class TempDir {
 public:
  TempDir() {
    root_ = make_temp_dir("portalsim-test");
    std::filesystem::create_directory(root_ / "w");
    std::filesystem::create_directory(root_ / "cap");
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir() {
    // A test may have made a folder read-only; give it back before removing everything.
    std::error_code ec;
    std::filesystem::permissions(root_, std::filesystem::perms::owner_all, std::filesystem::perm_options::add, ec);
    for (auto it = std::filesystem::recursive_directory_iterator(
             root_, std::filesystem::directory_options::skip_permission_denied, ec);
         !ec && it != std::filesystem::recursive_directory_iterator(); it.increment(ec)) {
      std::error_code ec2;
      if (it->is_directory(ec2) && !it->is_symlink(ec2))
        std::filesystem::permissions(it->path(), std::filesystem::perms::owner_all, std::filesystem::perm_options::add,
                                     ec2);
    }
    std::filesystem::remove_all(root_, ec);
  }
  std::filesystem::path w() const { return root_ / "w"; }
  std::filesystem::path cap() const { return root_ / "cap"; }

 private:
  std::filesystem::path root_;
};

struct Result {
  std::string command;
  bool exited = false;
  int status = -1;
  bool signaled = false;
  int signal = 0;
  bool timed_out = false;
  std::string out, err;
};

// Whether `needle` occurs in `hay` (messages and outputs the tests read).
inline bool has(const std::string& hay, const std::string& needle) { return hay.find(needle) != std::string::npos; }

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A CSV file's rows, each split at every comma (no quoting: portalsim's tables have none).
inline std::vector<std::vector<std::string>> csv_cells(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) f.push_back(c);
    rows.push_back(f);
  }
  return rows;
}

// A run folder's .portalsim/checkpoint.json "next" (-1 when absent or unreadable).
inline long long checkpoint_next(const std::filesystem::path& dir) {
  std::error_code ec;
  const std::filesystem::path p = dir / ".portalsim" / "checkpoint.json";
  if (!std::filesystem::exists(p, ec)) return -1;
  const nlohmann::json j = nlohmann::json::parse(slurp(p), nullptr, false);
  if (j.is_discarded() || !j.contains("next") || !j["next"].is_number_unsigned()) return -1;
  return static_cast<long long>(j["next"].get<uint64_t>());
}

inline void spit(const std::filesystem::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << text;
  if (!out) ADD_FAILURE() << "cannot write " << p;
}

inline std::string quoted(const std::string& a) {
  if (!a.empty() && a.find_first_of(" '\"&|;<>()$*?\\") == std::string::npos) return a;
  std::string q = "'";
  for (char c : a) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// What a run did, for a failed expectation; `limit`: the most of each stream shown.
inline std::string describe(const Result& r, size_t limit = std::string::npos) {
  std::ostringstream s;
  s << "command: " << r.command << "\n";
  if (r.timed_out)
    s << "timed out\n";
  else if (r.signaled)
    s << "killed by signal " << r.signal << "\n";
  else
    s << "exit status " << r.status << "\n";
  s << "--- stdout ---\n" << r.out.substr(0, limit) << "--- stderr ---\n" << r.err.substr(0, limit) << "---";
  return s.str();
}

struct Running {
  pid_t pid = -1;
  std::string command;
  std::filesystem::path out_path, err_path;
};

// Starts `program ARGS` with stdin from /dev/null and stdout/stderr captured in files
// under `cap`.
inline Running start_program(const std::filesystem::path& cap, const std::string& program,
                             const std::vector<std::string>& args) {
  static int counter = 0;
  const int n = ++counter;
  Running r;
  r.out_path = cap / (std::string("run") + std::to_string(n) + ".stdout");
  r.err_path = cap / (std::string("run") + std::to_string(n) + ".stderr");
  std::vector<std::string> argv_s{program};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  r.command = program == kBinary ? "portalsim" : program;
  for (const std::string& a : args) {
    r.command += ' ';
    r.command += quoted(a);
  }
  std::vector<char*> argv;
  for (std::string& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);

  const std::string out_s = r.out_path.string(), err_s = r.err_path.string();
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 1, out_s.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&fa, 2, err_s.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  const int rc = posix_spawn(&r.pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0 || r.pid <= 0) {
    ADD_FAILURE() << "cannot start " << program << ": " << std::strerror(rc);
    r.pid = -1;
  }
  return r;
}

// The same for portalsim itself.
inline Running start(const std::filesystem::path& cap, const std::vector<std::string>& args) {
  return start_program(cap, kBinary, args);
}

// Waits for a started run (at most limit_s, scaled, then kills that one child) and collects
// what it printed.
inline Result finish(const Running& r, int limit_s = 120) {
  Result res;
  res.command = r.command;
  if (r.pid <= 0) return res;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(limit_s * kTimeScale);
  int ws = 0;
  for (;;) {
    const pid_t w = ::waitpid(r.pid, &ws, WNOHANG);
    if (w == r.pid) break;
    if (w < 0 && errno != EINTR) {
      ADD_FAILURE() << "waitpid: " << std::strerror(errno);
      return res;
    }
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(r.pid, SIGKILL);
      ::waitpid(r.pid, &ws, 0);
      res.timed_out = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  res.exited = WIFEXITED(ws);
  if (res.exited) res.status = WEXITSTATUS(ws);
  res.signaled = WIFSIGNALED(ws);
  if (res.signaled) res.signal = WTERMSIG(ws);
  res.out = slurp(r.out_path);
  res.err = slurp(r.err_path);
  return res;
}

// `portalsim generate ARGS --quiet --out OUT`, run to its end (up to 300 s).
inline Result generate(const TempDir& t, std::vector<std::string> args, const std::filesystem::path& out) {
  args.insert(args.begin(), "generate");
  for (const char* a : {"--quiet", "--out"}) args.push_back(a);
  args.push_back(out.string());
  return finish(start(t.cap(), args), 300);
}

// `portalsim generate --spec SPEC --out OUT`, SPEC a file holding `toml` (up to 120 s): a
// spec file's errors name its line and key.
inline Result generate_spec(const TempDir& t, const std::string& toml, const std::filesystem::path& out) {
  const std::filesystem::path spec = t.w() / "spec.toml";
  spit(spec, toml);
  return finish(start(t.cap(), {"generate", "--spec", spec.string(), "--out", out.string()}), 120);
}

// `portalsim generate ARGS` is refused as a usage error (exit 2) whose message holds `says`,
// and makes no output folder.
inline void expect_generate_refused(const TempDir& t, const std::vector<std::string>& args, const std::string& says) {
  const std::filesystem::path out = t.w() / "refused";
  const Result r = generate(t, args, out);
  EXPECT_EQ(r.status, 2) << says;
  EXPECT_NE(r.err.find(says), std::string::npos) << says << ": " << r.err;
  EXPECT_FALSE(std::filesystem::exists(out)) << says;
}

// A spec file holding `toml` is refused naming `where` ("spec.toml:LINE: KEY"), and makes no
// output folder.
inline void expect_spec_refused(const TempDir& t, const std::string& toml, const std::string& where) {
  const std::filesystem::path out = t.w() / "refused";
  const Result r = generate_spec(t, toml, out);
  EXPECT_NE(r.status, 0) << where;
  EXPECT_NE(r.err.find(where), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out)) << where;
}

// True once the started run has ended (without reaping it).
inline bool has_ended(const Running& r) {
  siginfo_t info{};
  if (::waitid(P_PID, static_cast<id_t>(r.pid), &info, WEXITED | WNOHANG | WNOWAIT) != 0) return true;
  return info.si_pid != 0;
}

// A run killed with SIGKILL in the middle, and the checkpoint's "next" the kill left (-1
// without one).
struct Killed {
  Result result;
  long long next = -1;
};

// Waits (at most limit_s, scaled) until the run's checkpoint in `dir` reaches `at_least`,
// stops the run there (SIGSTOP, waiting until every thread has stopped, so that the
// checkpoint read then is the one the kill leaves), and kills it. Callers assert
// 0 < next < count: a kill before the first checkpoint or after the last is no mid-run kill.
inline Killed kill_mid_run(const Running& r, const std::filesystem::path& dir, long long at_least, int limit_s = 120) {
  Killed k;
  if (r.pid <= 0) return k;
  wait_until([&] { return checkpoint_next(dir) >= at_least || has_ended(r); }, limit_s);
  ::kill(r.pid, SIGSTOP);
  siginfo_t info{};
  ::waitid(P_PID, static_cast<id_t>(r.pid), &info, WSTOPPED | WEXITED | WNOWAIT);
  k.next = checkpoint_next(dir);
  ::kill(r.pid, SIGKILL);
  k.result = finish(r, 60);
  return k;
}

// Starts `portalsim generate SPEC --batch BATCH --out DIR --quiet` and kills it once its
// checkpoint reaches `at_least` (kill_mid_run).
inline Killed kill_generate(const TempDir& t, std::vector<std::string> spec, const std::string& batch,
                            const std::filesystem::path& dir, long long at_least) {
  spec.insert(spec.begin(), "generate");
  spec.insert(spec.end(), {"--batch", batch, "--out", dir.string(), "--quiet"});
  return kill_mid_run(start(t.cap(), spec), dir, at_least);
}

// Runs `script` with sh in a private mount namespace (unshare -m, as root) after mounting
// a tmpfs of `size` (e.g. "64k") at `mount_point`, read-only when asked. The mount is
// gone when the script ends, so the script itself lists what the test must inspect.
inline Result run_on_tmpfs(const std::filesystem::path& cap, const std::filesystem::path& mount_point,
                           const std::string& size, bool read_only, const std::string& script) {
  std::filesystem::create_directories(mount_point);
  const std::string mount = "mount -t tmpfs -o size=" + size + " tmpfs " + quoted(mount_point.string());
  const std::string ro = read_only ? " && mount -o remount,ro " + quoted(mount_point.string()) : "";
  return finish(start_program(cap, "/usr/bin/unshare", {"-m", "sh", "-c", mount + ro + " && " + script}));
}

// Runs several commands at once (they must write to different folders).
inline std::vector<Result> run_all(const TempDir& t, const std::vector<std::vector<std::string>>& commands) {
  std::vector<Running> running;
  for (const std::vector<std::string>& a : commands) running.push_back(start(t.cap(), a));
  std::vector<Result> results;
  for (const Running& r : running) results.push_back(finish(r));
  return results;
}

// `portalsim COMMAND ARGS --out OUT`.
inline std::vector<std::string> with_out(const std::string& command, const std::vector<std::string>& args,
                                         const std::filesystem::path& out) {
  std::vector<std::string> a{command};
  a.insert(a.end(), args.begin(), args.end());
  a.push_back("--out");
  a.push_back(out.string());
  return a;
}

// Every name in a folder, hidden ones included, sorted.
inline std::vector<std::string> names_in(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

inline std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  std::string cur;
  for (char c : text) {
    if (c == sep) {
      parts.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  parts.push_back(cur);
  return parts;
}

// The lines of stderr that carry a message (CLI11's "Run with --help" hint is not one).
inline std::vector<std::string> message_lines(const std::string& err) {
  std::vector<std::string> lines;
  for (const std::string& l : split(err, '\n'))
    if (!l.empty() && l != "Run with --help for more information.") lines.push_back(l);
  return lines;
}

// A command that succeeded: exit 0, no signal, no time-out, no error on stderr.
inline void expect_success(const Result& r) {
  EXPECT_FALSE(r.timed_out) << describe(r, 4000);
  EXPECT_FALSE(r.signaled) << describe(r, 4000);
  EXPECT_TRUE(r.exited && r.status == 0) << describe(r, 4000);
  EXPECT_FALSE(has(r.err, "error")) << describe(r, 4000);
}

// A rejected command: non-zero exit, no signal, one stderr message naming every needle, nothing
// on stdout, and the output folder absent (or still empty when it existed before the run).
inline void expect_clean_failure(const Result& r, const std::filesystem::path& out, bool out_existed,
                                 const std::vector<std::string>& needles) {
  std::error_code ec;
  if (r.exited && r.status == 0) {
    ADD_FAILURE() << "portalsim accepted a command it must reject\n" << describe(r, 4000);
    if (std::filesystem::exists(out, ec) && !out_existed) ADD_FAILURE() << out << " was created";
    return;
  }
  SCOPED_TRACE(describe(r, 4000));
  EXPECT_FALSE(r.timed_out);
  EXPECT_FALSE(r.signaled) << "portalsim was killed by signal " << r.signal << " (" << strsignal(r.signal) << ")";
  EXPECT_TRUE(r.exited);
  EXPECT_NE(r.status, 0) << "a rejected command must exit non-zero";
  EXPECT_EQ(message_lines(r.err).size(), 1u) << "stderr should hold exactly one message";
  for (const std::string& n : needles) EXPECT_TRUE(has(r.err, n)) << "stderr does not name \"" << n << "\"";
  EXPECT_EQ(r.out, "") << "nothing should be printed on stdout";
  if (out_existed) {
    EXPECT_TRUE(std::filesystem::is_directory(out, ec)) << out << " existed before the run and must still be there";
    EXPECT_TRUE(names_in(out).empty()) << out << " must stay empty, holds: " << testing::PrintToString(names_in(out));
  } else if (std::filesystem::exists(out, ec)) {
    EXPECT_TRUE(std::filesystem::is_directory(out, ec) && names_in(out).empty())
        << out << " did not exist before and must not hold anything after a failed run; holds "
        << testing::PrintToString(names_in(out));
  }
}

// One command that must be rejected: `portalsim COMMAND ARGS --out OUT` with OUT absent, and
// (also_existing) once more with OUT an empty folder made beforehand.
struct Rejection {
  std::vector<std::string> args;
  std::vector<std::string> needles;
  bool also_existing = false;
};

// Runs every case of `command` at once; each must be rejected cleanly with a message naming
// its needles.
inline void expect_all_rejected(const TempDir& t, const std::string& command, const std::vector<Rejection>& cases) {
  static int counter = 0;
  struct Check {
    const Rejection* c;
    std::filesystem::path out;
    bool existed;
  };
  std::vector<Check> checks;
  for (const Rejection& c : cases) {
    const int n = ++counter;
    checks.push_back({&c, t.w() / (std::string("out-fresh-") + std::to_string(n)), false});
    if (c.also_existing) {
      checks.push_back({&c, t.w() / (std::string("out-existing-") + std::to_string(n)), true});
      std::filesystem::create_directory(checks.back().out);
    }
  }
  std::vector<std::vector<std::string>> commands;
  for (const Check& k : checks) commands.push_back(with_out(command, k.c->args, k.out));
  const std::vector<Result> r = run_all(t, commands);
  for (size_t i = 0; i < checks.size(); ++i) {
    SCOPED_TRACE(checks[i].existed ? "output folder existed (empty) before the run"
                                   : "output folder absent before the run");
    expect_clean_failure(r[i], checks[i].out, checks[i].existed, checks[i].c->needles);
  }
}

}  // namespace portalsim::test
