// Writing a folder of outputs all or nothing: files are written under a staging folder
// and moved into place by commit(); anything uncommitted is removed on destruction.
#pragma once
#include <string>
#include <vector>

namespace portalsim {

class StagedFolder {
 public:
  // Creates `final_dir` if needed and a hidden staging folder inside it. Throws
  // OutputError naming the folder when it cannot be created or written.
  explicit StagedFolder(const std::string& final_dir);
  StagedFolder(const StagedFolder&) = delete;
  StagedFolder& operator=(const StagedFolder&) = delete;
  ~StagedFolder();

  // Where to write `name` now; it reaches final_dir/name at commit().
  std::string path(const std::string& name);
  // The staging folder itself (files written there without path() are dropped).
  const std::string& dir() const { return staging_; }
  void commit();

 private:
  std::string final_dir_, staging_;
  std::vector<std::string> names_;
  std::vector<std::string> created_;  // folders this object made, outermost first
  bool committed_ = false;
};

// Writes `text` to `path` through a temporary name and a rename. Throws OutputError.
void write_text_atomic(const std::string& path, const std::string& text);

}  // namespace portalsim
