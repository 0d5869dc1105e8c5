#include "sink/output_folder.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "base/error.h"
#include "io/input_file.h"

namespace portalsim {

namespace fs = std::filesystem;

std::string read_state_file(const std::string& path) {
  try {
    return io::read_file(path, "run state", io::kMaxTextBytes);
  } catch (const InputError& e) {
    throw OutputError(e.what());
  }
}

FolderState output_folder_state(const std::string& dir) {
  std::error_code ec;
  const fs::file_status link = fs::symlink_status(dir, ec);
  if (!fs::exists(link)) return FolderState::missing;
  const fs::file_status target = fs::status(dir, ec);
  if (fs::is_symlink(link) && !fs::exists(target))
    throw OutputError(dir + ": is a symlink to nothing (" + fs::read_symlink(dir, ec).string() +
                      "); create its target folder or choose another --out");
  if (!fs::is_directory(target)) throw OutputError(dir + ": exists and is not a folder");
  fs::directory_iterator it(dir, ec);
  if (ec) throw OutputError(dir + ": cannot read the output folder: " + ec.message());
  for (; it != fs::directory_iterator(); it.increment(ec)) {
    if (ec) throw OutputError(dir + ": cannot read the output folder: " + ec.message());
    if (!it->path().filename().string().starts_with(kStateDir)) return FolderState::has_files;
  }
  return FolderState::empty;
}

FolderLock::FolderLock(const std::string& dir) {
  const fs::path state = fs::path(dir) / kStateDir, path = state / "lock";
  path_ = path.string();
  std::error_code ec;
  fs::create_directories(state, ec);
  if (ec) throw OutputError(dir + ": cannot create " + state.string() + ": " + ec.message());
  // What this constructor made goes again when it throws (a full disk fails the PID's
  // write): .portalsim/ only if empty, so a folder's other state is never touched.
  const auto fail = [&](const std::string& message) {
    fs::remove(state, ec);
    throw OutputError(message);
  };
  // The holder removes the file on release: a lock taken on a file already unlinked is
  // no lock, so try again on the new one.
  for (int attempt = 0;; ++attempt) {
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd_ < 0) fail(path.string() + ": cannot open the lock file: " + std::strerror(errno));
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      char pid[32] = {};
      const ssize_t n = ::pread(fd_, pid, sizeof pid - 1, 0);
      ::close(fd_);
      fd_ = -1;
      if (err != EWOULDBLOCK) throw OutputError(path.string() + ": cannot lock: " + std::strerror(err));
      std::string holder(pid, n > 0 ? static_cast<size_t>(n) : 0);
      while (!holder.empty() && (holder.back() == '\n' || holder.back() == ' ')) holder.pop_back();
      throw OutputError(dir + ": another portalsim run (PID " + (holder.empty() ? "unknown" : holder) +
                        ") is writing here; wait for it to finish or stop it");
    }
    struct stat held, now;
    if (::fstat(fd_, &held) == 0 && ::stat(path.c_str(), &now) == 0 && held.st_ino == now.st_ino &&
        held.st_dev == now.st_dev)
      break;
    ::close(fd_);
    fd_ = -1;
    if (attempt == 10) throw OutputError(path.string() + ": the lock file keeps changing; is another run starting?");
  }
  const std::string me = std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, me.data(), me.size(), 0) != static_cast<ssize_t>(me.size())) {
    const int err = errno;
    release();
    fail(path.string() + ": cannot write the lock file: " + std::strerror(err));
  }
}

FolderLock::~FolderLock() { release(); }

void FolderLock::release() {
  if (fd_ < 0) return;
  std::error_code ec;
  fs::remove(path_, ec);                          // before the unlock, so that a waiting run finds a fresh file
  fs::remove(fs::path(path_).parent_path(), ec);  // only if empty
  ::close(fd_);                                   // releases the flock
  fd_ = -1;
}

}  // namespace portalsim
