// Scenario lists (generate --scenarios FILE): CSV with a header naming subject, region1..
// regionR (R the catalogue's regions, 13 in the built-in one) and optionally label
// (yes/no/positive/negative/1/0), index (ignored: scenario i of the list is index i) and the
// randomised objects' columns (rotation1..R, scale1..R, flip1..R: all 3 R or none).
// Subjects are 1-based. Errors name file, line and column or field.
//
// Fields are read as RFC 4180 does: a field may be quoted, with "" for a quote inside; spaces
// round an unquoted field are dropped. No field of a scenario list can hold a line break (a
// quoted field still open at its line's end is refused), so a row is a line: a file is
// read as a stream, and rows are counted, and skipped, by their line ends alone.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "scene/scene.h"

namespace portalsim {

// What a listed scenario's row records of its randomised objects, to be checked against
// the draws of the run that re-makes it; `line` is the row's line in the file.
struct ListedTransforms {
  size_t line = 0;
  std::array<ObjectTransform, kMaxRegions> t;  // identity where the region has no object
};

inline constexpr size_t kMaxFieldBytes = 256;

// A list's columns (from its header line) and the parsing of its rows.
class ScenarioRows {
 public:
  // `header`: the header line (no line end); `line` its line number in `path`. With
  // `own_bodies`, the list of a run of per-scenario bodies: every subject is 0 (its own body).
  // `drawn`: the columns of the numbers a run draws per scenario (plan/knobs.h,
  // drawn_number_keys), which record its draws: a list skips them, as the seed draws them again.
  ScenarioRows(const Catalogue& cat, std::string_view header, const std::string& path, size_t line,
               bool own_bodies = false, const std::vector<std::string>& drawn = {});
  bool has_transforms() const { return transform_columns_ != 0; }
  // Object tokens already read, per thread: lists repeat a few names millions of times.
  struct TokenHash {
    using is_transparent = void;
    size_t operator()(std::string_view s) const { return std::hash<std::string_view>()(s); }
  };
  using Tokens = std::unordered_map<std::string, int16_t, TokenHash, std::equal_to<>>;
  // One row (its line end dropped, CRLF too); `t` gets its transforms, if it has any.
  // Checks the row's bytes as check_text does.
  Scenario parse(std::string_view row, size_t line, ListedTransforms* t, Tokens& tokens) const;
  // Whether a line is a row: not empty and not a comment (#...).
  static bool is_row(std::string_view line) { return !line.empty() && line != "\r" && line[0] != '#'; }

 private:
  const Catalogue& cat_;
  std::string path_;
  bool own_bodies_;
  size_t fields_ = 0;
  int col_subject_ = -1, col_label_ = -1;
  std::array<int, kMaxRegions> col_region_{};
  std::array<std::array<int, kMaxRegions>, 3> col_transform_{};
  int transform_columns_ = 0;
};

// A whole list in memory (`text`, which `path` names in errors): its scenarios and, where
// it records them, their transforms.
std::vector<Scenario> parse_scenario_list(const Catalogue& cat, std::string_view text, const std::string& path,
                                          std::vector<ListedTransforms>* transforms = nullptr,
                                          const std::vector<std::string>& drawn = {});

// A list file of any length, read as a stream: opening it reads the header and counts the
// rows (by their line ends, with a mark every so many rows); read() parses the rows asked
// for, from the nearest mark. Memory stays flat whatever the file's length.
class ScenarioListFile {
 public:
  // `own_bodies` and `drawn`: as ScenarioRows's (evaluate reads a run of per-scenario bodies' list).
  ScenarioListFile(const Catalogue& cat, std::string path, bool own_bodies = false,
                   const std::vector<std::string>& drawn = {});
  ~ScenarioListFile();
  ScenarioListFile(const ScenarioListFile&) = delete;
  ScenarioListFile& operator=(const ScenarioListFile&) = delete;

  uint64_t size() const { return rows_; }
  bool has_transforms() const { return columns_->has_transforms(); }
  // Rows [at, at + n) into out[0..n) (and t[0..n) where the list has transforms), parsed on
  // up to `threads` threads. A bad row throws InputError naming the first one's line.
  void read(uint64_t at, size_t n, unsigned threads, Scenario* out, ListedTransforms* t) const;

  // Tests: the bytes read at a time (rows straddle the pieces), and rows between marks.
  static void set_piece_bytes_for_tests(size_t bytes, uint64_t mark_rows);

 private:
  struct Cursor;
  struct Mark {
    uint64_t offset = 0, line = 0;  // where row k * mark_rows starts
  };
  void seek(uint64_t row) const;  // the cursor to the start of `row`
  std::string path_;
  int fd_ = -1;
  std::unique_ptr<ScenarioRows> columns_;
  uint64_t rows_ = 0, mark_rows_ = 0;
  std::vector<Mark> marks_;
  mutable std::mutex m_;  // read() moves the one cursor
  std::unique_ptr<Cursor> cursor_;
  mutable uint64_t cursor_row_ = 0;
};

}  // namespace portalsim
