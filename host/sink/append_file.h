// A file written by appending, with its length and CRC-32 kept as it grows, so a run
// can checkpoint where it stands and a resumed run can truncate back to that point.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>

namespace portalsim {

struct FileState {
  std::string name;   // relative to the output folder, final name
  uint64_t bytes = 0;
  uint32_t crc32 = 0;
};

class AppendFile {
 public:
  // Opens dir/(name + ".partial"). With `resume`, truncates it to resume->bytes (it must
  // be at least that long) and continues its CRC; otherwise creates it empty.
  AppendFile(const std::string& dir, const std::string& name, const FileState* resume = nullptr);
  AppendFile(const AppendFile&) = delete;
  AppendFile& operator=(const AppendFile&) = delete;
  ~AppendFile();

  void append(std::string_view data);
  void append(const void* data, size_t n) { append(std::string_view(static_cast<const char*>(data), n)); }
  // Writes `data` at `offset` (an already written header being finalised); no CRC update.
  void overwrite(uint64_t offset, std::string_view data);
  const FileState& state() const { return state_; }
  // Closes and renames the partial file to its final name.
  void finish();
  // Recomputes the CRC of the whole file (after an overwrite).
  void recompute_crc();

 private:
  std::string dir_, partial_, final_;
  FileState state_;
  int fd_ = -1;
};

}  // namespace portalsim
