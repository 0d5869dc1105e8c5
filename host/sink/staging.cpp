#include "sink/staging.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include "base/error.h"
#include "io/output_file.h"
#include "sink/output_folder.h"

namespace portalsim {

namespace fs = std::filesystem;

StagedFolder::StagedFolder(const std::string& final_dir) : final_dir_(final_dir) {
  if (final_dir_.empty()) throw OutputError("--out: empty folder name");
  std::error_code ec;
  (void)output_folder_state(final_dir_);  // refuses a file or a dangling symlink
  // Remember each missing ancestor, so that a failure removes all that was made (and
  // nothing else: a symlink counts as existing, whatever it points to).
  for (fs::path p = fs::absolute(final_dir_, ec).lexically_normal();
       !p.empty() && !fs::exists(fs::symlink_status(p, ec)); p = p.parent_path()) {
    created_.insert(created_.begin(), p.string());
    if (p == p.parent_path()) break;
  }
  if (!created_.empty()) {
    fs::create_directories(final_dir_, ec);
    if (ec) {
      for (auto it = created_.rbegin(); it != created_.rend(); ++it) fs::remove(*it, ec);
      throw OutputError(final_dir_ + ": cannot create the output folder: " + ec.message());
    }
  }
  staging_ = (fs::path(final_dir_) / (".portalsim-staging-" + std::to_string(::getpid()))).string();
  fs::remove_all(staging_, ec);
  fs::create_directory(staging_, ec);
  if (ec) {
    const std::string why = ec.message();
    for (auto it = created_.rbegin(); it != created_.rend(); ++it) fs::remove(*it, ec);
    throw OutputError(final_dir_ + ": cannot write into the output folder: " + why);
  }
}

StagedFolder::~StagedFolder() {
  std::error_code ec;
  fs::remove_all(staging_, ec);
  if (!committed_)  // fs::remove only takes empty folders: nothing of anyone else's goes
    for (auto it = created_.rbegin(); it != created_.rend(); ++it) fs::remove(*it, ec);
}

std::string StagedFolder::path(const std::string& name) {
  names_.push_back(name);
  return (fs::path(staging_) / name).string();
}

void StagedFolder::commit() {
  std::vector<std::string> moved;
  for (const std::string& name : names_) {
    std::error_code ec;
    fs::rename(fs::path(staging_) / name, fs::path(final_dir_) / name, ec);
    if (ec) {
      for (const std::string& m : moved) fs::remove(fs::path(final_dir_) / m, ec);
      throw OutputError((fs::path(final_dir_) / name).string() + ": cannot move into place: " + ec.message());
    }
    moved.push_back(name);
  }
  committed_ = true;
}

void write_text_atomic(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp-" + std::to_string(::getpid());
  io::write_file(tmp, text);
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw OutputError(path + ": cannot move into place: " + ec.message());
  }
}

}  // namespace portalsim
