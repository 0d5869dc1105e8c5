// portalsim merge: the parts of one data set (generate --shard i/k, made anywhere) joined
// into the folder one run makes, byte for byte.
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "base/error.h"
#include "cli/commands.h"
#include "schedule/join.h"
#include "sink/output_folder.h"

namespace portalsim::cli {

namespace {

namespace fs = std::filesystem;

struct MergeOptions {
  std::vector<std::string> parts;
  std::string out;
};

int merge(const MergeOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  if (o.out.empty()) throw InputError("--out: empty folder name");
  const std::vector<Part> parts = read_parts(o.parts);
  for (const Part& p : parts) {
    std::error_code ec;
    if (fs::equivalent(p.dir, o.out, ec)) throw InputError("--out: " + o.out + " is one of the parts");
  }
  const FolderState state = output_folder_state(o.out);
  if (state == FolderState::has_files) throw OutputError(o.out + ": is not empty; choose a new folder");
  std::error_code ec;
  if (state == FolderState::missing) {
    fs::create_directories(o.out, ec);
    if (ec) throw OutputError(o.out + ": cannot create the output folder: " + ec.message());
  }
  JoinResult r;
  bool locked = false;
  try {
    const FolderLock lock(o.out);
    locked = true;
    r = join_parts(parts, o.out, *single_rank());
  } catch (...) {
    // Nothing half-made stays: the folder was empty, or this merge made it. A folder
    // another run holds is left to it.
    if (locked && state == FolderState::missing) {
      fs::remove_all(o.out, ec);
    } else if (locked) {
      for (const auto& e : fs::directory_iterator(o.out, ec))
        if (!e.path().filename().string().starts_with(kStateDir)) fs::remove_all(e.path(), ec);
      fs::remove_all(fs::path(o.out) / kStateDir / "join", ec);
      fs::remove(fs::path(o.out) / kStateDir, ec);  // only when empty
    }
    throw;
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%s: %zu parts joined: %llu scenarios (positive %llu, negative %llu), %.1f MiB of outputs in %.2f s\n",
              o.out.c_str(), parts.size(), static_cast<unsigned long long>(r.count),
              static_cast<unsigned long long>(r.positive), static_cast<unsigned long long>(r.negative),
              r.bytes / 1048576.0, s);
  return 0;
}

}  // namespace

std::function<int()> add_merge(CLI::App& app) {
  auto o = std::make_shared<MergeOptions>();
  CLI::App* sub = app.add_subcommand(
      "merge", "join folders made with generate --shard i/k into the data set one run makes, byte for byte");
  sub->add_option("parts", o->parts, "the finished part folders, in any order")->required();
  sub->add_option("--out", o->out, "output folder (new or empty)")->required();
  return [o] { return merge(*o); };
}

}  // namespace portalsim::cli
