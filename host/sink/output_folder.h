// The rules every command's output folder follows (docs/reference/outputs.md, "Output folders"): it is a
// folder, a symlink to one, or does not exist yet; a file or a dangling symlink is
// refused and never removed; one run at a time holds it, through a lock in .portalsim/.
#pragma once
#include <string>

namespace portalsim {

// The hidden folder of portalsim's own state inside an output folder.
inline constexpr const char* kStateDir = ".portalsim";

enum class FolderState { missing, empty, has_files };

// A file of a run's own state (checkpoint, manifest, job), read through the input layer's
// checks; OutputError when it cannot be (the folder is the run's output).
std::string read_state_file(const std::string& path);

// What `dir` holds, not counting entries whose names start with ".portalsim" (the
// state and staging folders of portalsim's own runs). Throws OutputError when `dir`
// is a file, a dangling symlink or unreadable.
FolderState output_folder_state(const std::string& dir);

// An exclusive flock on dir/.portalsim/lock, created if needed; the file holds the PID.
// Throws OutputError naming the PID of the run that holds it. On release the lock file
// goes, and .portalsim/ too when nothing else is in it: a refused or finished run leaves
// the folder as it found it.
class FolderLock {
 public:
  explicit FolderLock(const std::string& dir);
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;
  ~FolderLock();

 private:
  void release();  // removes the lock file (and .portalsim/ when empty), then unlocks
  int fd_ = -1;
  std::string path_;
};

}  // namespace portalsim
