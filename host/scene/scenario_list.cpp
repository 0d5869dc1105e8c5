#include "scene/scenario_list.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <cstring>
#include <exception>

#include "base/error.h"
#include "base/parallel.h"
#include "base/sizes.h"
#include "io/input_file.h"
#include "io/table_fields.h"
#include "scene/bodies.h"
#include "scene/clothing.h"

namespace portalsim {

namespace {

std::string_view without_line_end(std::string_view l) {
  if (l.ends_with('\n')) l.remove_suffix(1);
  if (l.ends_with('\r')) l.remove_suffix(1);
  return l;
}

// One line's fields (the line without its line end) into f[0..count), reusing f's strings.
// Throws InputError "path:line: column k: why".
size_t split_fields(std::string_view line, std::vector<std::string>& f, const std::string& path, size_t lineno) {
  return io::split_fields(line, f, io::Quoting::csv, path, lineno, kMaxFieldBytes);
}

constexpr std::array<const char*, 3> kTransformColumns = {"rotation", "scale", "flip"};

// Pieces of the file read at a time, and rows between marks (tests lower both).
std::atomic<size_t> g_piece_bytes{kIoPieceBytes};
std::atomic<uint64_t> g_mark_rows{1u << 16};

}  // namespace

ScenarioRows::ScenarioRows(const Catalogue& cat, std::string_view header_line, const std::string& path, size_t lineno,
                           bool own_bodies, const std::vector<std::string>& drawn)
    : cat_(cat), path_(path), own_bodies_(own_bodies) {
  std::vector<std::string> header;
  header.resize(split_fields(without_line_end(header_line), header, path, lineno));
  fields_ = header.size();
  col_region_.fill(-1);
  for (auto& c : col_transform_) c.fill(-1);
  const std::string at = path + ":" + std::to_string(lineno);
  const int R = cat.region_count();
  const std::string regions = "regions 1 to " + std::to_string(R);
  // "region", "rotation", ... followed by 1..R: the region (1-based), 0 for another name,
  // -1 for a number out of range.
  const auto numbered = [R](const std::string& h, const std::string& stem) {
    if (h.rfind(stem, 0) != 0 || h.size() <= stem.size() || h.size() > stem.size() + 2 ||
        h.find_first_not_of("0123456789", stem.size()) != std::string::npos)
      return 0;
    const int r = std::stoi(h.substr(stem.size()));
    return r >= 1 && r <= R ? r : -1;
  };
  for (size_t c = 0; c < header.size(); ++c) {
    const std::string h = normalise_name(header[c]);
    const std::string column = at + ": column " + std::to_string(c + 1) + " \"" + header[c] + "\": ";
    for (size_t d = 0; d < c; ++d)
      if (normalise_name(header[d]) == h) throw InputError(column + "duplicates column " + std::to_string(d + 1));
    if (h == "subject")
      col_subject_ = static_cast<int>(c);
    else if (h == "label" || h == "class" || h == "threat")
      col_label_ = static_cast<int>(c);
    else if (int r = numbered(h, "region"); r != 0) {
      if (r < 0) throw InputError(column + "there are " + regions + " only");
      col_region_[r - 1] = static_cast<int>(c);
    } else if (h == "index" ||
               std::any_of(drawn.begin(), drawn.end(), [&](const std::string& k) { return normalise_name(k) == h; }) ||
               std::any_of(kBodyColumns.begin(), kBodyColumns.end(),
                           [&](const char* k) { return normalise_name(k) == h; }) ||
               std::any_of(kClothingColumns.begin(), kClothingColumns.end(),
                           [&](const char* k) { return normalise_name(k) == h; }) ||
               std::any_of(kRawGridColumns.begin(), kRawGridColumns.end(),
                           [&](const char* k) { return normalise_name(k) == h; })) {
      // A drawn knob's, body's or outfit's column records the run's draw; a run draws it
      // again from its seed.
    } else if (
        int t = 0, tr = 0; [&] {
          for (t = 0; t < 3; ++t)
            if ((tr = numbered(h, kTransformColumns[t])) != 0) return true;
          return false;
        }()) {
      if (tr < 0) throw InputError(column + "there are " + regions + " only");
      col_transform_[t][tr - 1] = static_cast<int>(c);
      ++transform_columns_;
    } else {
      throw InputError(column + "unknown column (expected subject, region1..region" + std::to_string(R) + ", label)");
    }
  }
  const std::string rn = "1.." + std::to_string(R);
  if (transform_columns_ != 0 && transform_columns_ != 3 * R)
    throw InputError(at + ": header: the randomised objects' columns come together: rotation" + rn + ", scale" + rn +
                     " and flip" + rn + " (found " + std::to_string(transform_columns_) + " of " +
                     std::to_string(3 * R) + ")");
  if (col_subject_ < 0) throw InputError(at + ": header: no \"subject\" column");
  for (int r = 0; r < R; ++r)
    if (col_region_[r] < 0) throw InputError(at + ": header: no \"region" + std::to_string(r + 1) + "\" column");
}

Scenario ScenarioRows::parse(std::string_view row, size_t lineno, ListedTransforms* lt, Tokens& tokens) const {
  io::check_line(row, path_, lineno);
  thread_local std::vector<std::string> f;
  const size_t count = split_fields(without_line_end(row), f, path_, lineno);
  const auto at = [&] { return path_ + ":" + std::to_string(lineno); };
  if (count != fields_)
    throw InputError(at() + ": expected " + std::to_string(fields_) + " fields, found " + std::to_string(count));
  Scenario s;
  const std::string& subj = f[col_subject_];
  int sv = 0;
  if (own_bodies_) {
    if (subj != "0") throw InputError(at() + ": subject: \"" + subj + "\" is not 0 (each scenario's own body)");
  } else if (subj.empty() || subj.size() > 3 || subj.find_first_not_of("0123456789") != std::string::npos ||
             (sv = std::stoi(subj)) < 1 || sv > static_cast<int>(cat_.subjects.size())) {
    throw InputError(at() + ": subject: \"" + subj + "\" is not a subject number (1 to " +
                     std::to_string(cat_.subjects.size()) + ")" +
                     (subj == "0" ? "; 0 is a per-scenario body's, which a list cannot name" : ""));
  }
  s.subject = own_bodies_ ? 0 : sv - 1;
  for (int r = 0; r < cat_.region_count(); ++r) {
    static const std::string kNone = "none";
    const std::string& token = f[col_region_[r]].empty() ? kNone : f[col_region_[r]];
    if (auto it = tokens.find(token); it != tokens.end()) {
      s.objects[r] = it->second;
      continue;
    }
    s.objects[r] = parse_object_token(cat_, token, at() + ": region" + std::to_string(r + 1));
    if (tokens.size() < 4096) tokens.emplace(token, s.objects[r]);
  }
  if (col_label_ >= 0) {
    const std::string l = normalise_name(f[col_label_]);
    if (l == "yes" || l == "positive" || l == "1" || l == "threat")
      s.label = 1;
    else if (l == "no" || l == "negative" || l == "0")
      s.label = 0;
    else
      throw InputError(at() + ": label: \"" + f[col_label_] + "\" is not yes/no");
  } else {
    s.label = -1;  // the caller's rule decides
  }
  if (transform_columns_) {
    ListedTransforms got{lineno, {}};
    for (int r = 0; r < cat_.region_count(); ++r) {
      const std::array<const std::string*, 3> v = {&f[col_transform_[0][r]], &f[col_transform_[1][r]],
                                                   &f[col_transform_[2][r]]};
      const std::string name = ": region" + std::to_string(r + 1) + " ";
      if (s.objects[r] == kNoObject) {
        for (int t = 0; t < 3; ++t)
          if (!v[t]->empty())
            throw InputError(at() + name + kTransformColumns[t] + ": \"" + *v[t] + "\" for an empty region");
        continue;
      }
      double num[2] = {0, 0};
      for (int t = 0; t < 2; ++t) {
        const char* end = v[t]->data() + v[t]->size();
        const auto res = std::from_chars(v[t]->data(), end, num[t]);
        if (v[t]->empty() || res.ec != std::errc() || res.ptr != end || !std::isfinite(num[t]))
          throw InputError(at() + name + kTransformColumns[t] + ": \"" + *v[t] + "\" is not a number");
      }
      if (*v[2] != "0" && *v[2] != "1") throw InputError(at() + name + "flip: \"" + *v[2] + "\" is not 0 or 1");
      got.t[r] = ObjectTransform{num[0], num[1], *v[2] == "1"};
    }
    if (lt) *lt = got;
  }
  return s;
}

std::vector<Scenario> parse_scenario_list(const Catalogue& cat, std::string_view raw, const std::string& path,
                                          std::vector<ListedTransforms>* transforms,
                                          const std::vector<std::string>& drawn) {
  // A BOM is allowed: spreadsheets write one. CRLF line ends are too.
  std::string_view text = io::check_text(raw, path, io::Bom::skip);
  size_t lineno = 0;
  const auto next_line = [&](std::string_view& l) {
    if (text.empty()) return false;
    const size_t end = text.find('\n');
    l = text.substr(0, end == std::string_view::npos ? text.size() : end + 1);
    text.remove_prefix(l.size());
    ++lineno;
    return true;
  };
  std::string_view line;
  std::unique_ptr<ScenarioRows> rows;
  while (!rows && next_line(line)) {
    const std::string_view body = without_line_end(line);
    if (!body.empty() && body[0] != '#') rows = std::make_unique<ScenarioRows>(cat, line, path, lineno, false, drawn);
  }
  if (!rows) throw InputError(path + ": empty scenario file (expected a header line)");
  std::vector<Scenario> out;
  ScenarioRows::Tokens tokens;
  while (next_line(line)) {
    if (!ScenarioRows::is_row(line.substr(0, line.size() - (line.ends_with('\n') ? 1 : 0)))) continue;
    ListedTransforms t;
    out.push_back(rows->parse(line, lineno, &t, tokens));
    if (rows->has_transforms() && transforms) transforms->push_back(t);
  }
  if (out.empty()) throw InputError(path + ": no scenarios after the header");
  return out;
}

// ---------------------------------------------------------------------------------------------

// Lines of the file from a given place, a piece at a time: a line may straddle pieces.
struct ScenarioListFile::Cursor {
  int fd = -1;
  const std::string* path = nullptr;
  std::string buf;
  size_t pos = 0;           // the next unread byte of buf
  uint64_t buf_offset = 0;  // the file offset of buf[0]
  uint64_t line = 0;        // the line just returned (the next is line + 1)
  bool eof = false;

  void reset(uint64_t offset, uint64_t line_before) {
    buf.clear();
    pos = 0;
    buf_offset = offset;
    line = line_before;
    eof = false;
  }
  uint64_t offset() const { return buf_offset + pos; }

  // The next line, with its line end where it has one; false past the last.
  bool next(std::string_view& l) {
    for (;;) {
      const char* s = buf.data() + pos;
      const size_t avail = buf.size() - pos;
      if (const void* nl = std::memchr(s, '\n', avail)) {
        l = std::string_view(s, static_cast<size_t>(static_cast<const char*>(nl) - s) + 1);
        pos += l.size();
        ++line;
        return true;
      }
      if (eof) {
        if (avail == 0) return false;
        l = std::string_view(s, avail);
        pos += avail;
        ++line;
        return true;
      }
      if (avail > io::kMaxLineBytes + 2) {  // a line longer than any text file may hold
        io::check_line(std::string_view(s, avail), *path, line + 1);
        throw InputError(io::where(*path, line + 1, 1) + ": line longer than " + std::to_string(io::kMaxLineBytes) +
                         " bytes");
      }
      // Keep the line begun, read the next piece after it.
      buf.erase(0, pos);
      buf_offset += pos;
      pos = 0;
      const size_t kept = buf.size(), piece = g_piece_bytes;
      buf.resize(kept + piece);
      ssize_t r;
      do {
        r = ::pread(fd, buf.data() + kept, piece, static_cast<off_t>(buf_offset + kept));
      } while (r < 0 && errno == EINTR);
      if (r < 0) throw InputError(*path + ": cannot read the scenario file: " + std::strerror(errno));
      buf.resize(kept + static_cast<size_t>(r));
      if (r == 0) eof = true;
    }
  }
};

void ScenarioListFile::set_piece_bytes_for_tests(size_t bytes, uint64_t mark_rows) {
  g_piece_bytes = bytes;
  g_mark_rows = mark_rows;
}

ScenarioListFile::ScenarioListFile(const Catalogue& cat, std::string path, bool own_bodies,
                                   const std::vector<std::string>& drawn)
    : path_(std::move(path)), mark_rows_(g_mark_rows), cursor_(std::make_unique<Cursor>()) {
  fd_ = io::open_regular_file(path_, "scenario file");
  Cursor& c = *cursor_;
  c.fd = fd_;
  c.path = &path_;
  c.reset(0, 0);
  std::string_view line;
  // The header: the first line that is not empty or a comment. A BOM is allowed before it
  // (spreadsheets write one), and CRLF line ends.
  while (!columns_ && c.next(line)) {
    if (c.line == 1 && line.starts_with("\xEF\xBB\xBF")) line.remove_prefix(3);
    io::check_line(line, path_, c.line);
    const std::string_view body = without_line_end(line);
    if (!body.empty() && body[0] != '#')
      columns_ = std::make_unique<ScenarioRows>(cat, line, path_, c.line, own_bodies, drawn);
  }
  if (!columns_) throw InputError(path_ + ": empty scenario file (expected a header line)");
  // Count the rows, marking where every mark_rows_-th starts; no row is parsed here.
  for (uint64_t at = c.offset(); c.next(line); at = c.offset()) {
    if (!ScenarioRows::is_row(line.substr(0, line.size() - (line.ends_with('\n') ? 1 : 0)))) continue;
    if (rows_ % mark_rows_ == 0) marks_.push_back(Mark{at, c.line});
    ++rows_;
  }
  if (rows_ == 0) throw InputError(path_ + ": no scenarios after the header");
  cursor_row_ = rows_;  // nowhere: the first read() seeks
}

ScenarioListFile::~ScenarioListFile() {
  if (fd_ >= 0) ::close(fd_);
}

void ScenarioListFile::seek(uint64_t row) const {
  const Mark& m = marks_[row / mark_rows_];
  cursor_->reset(m.offset, m.line - 1);
  // Past the rows from the mark to `row`: read() goes on from the line after the last.
  std::string_view line;
  for (uint64_t r = row / mark_rows_ * mark_rows_; r < row && cursor_->next(line);)
    if (ScenarioRows::is_row(line.substr(0, line.size() - (line.ends_with('\n') ? 1 : 0)))) ++r;
  cursor_row_ = row;
}

void ScenarioListFile::read(uint64_t at, size_t n, unsigned threads, Scenario* out, ListedTransforms* t) const {
  if (at > rows_ || n > rows_ - at)
    throw InputError(path_ + ": rows " + std::to_string(at) + ".." + std::to_string(at + n) + " are past its end (" +
                     std::to_string(rows_) + " rows)");
  // The rows' lines, copied out of the cursor's pieces (they straddle them), then parsed
  // in parallel.
  std::string text;
  std::vector<size_t> start(n + 1), line(n);
  {
    std::lock_guard<std::mutex> lock(m_);
    if (cursor_row_ != at) seek(at);
    std::string_view l;
    for (size_t k = 0; k < n;) {
      if (!cursor_->next(l)) throw InputError(path_ + ": changed while it was read (fewer rows than counted)");
      if (!ScenarioRows::is_row(l.substr(0, l.size() - (l.ends_with('\n') ? 1 : 0)))) {
        io::check_line(l, path_, cursor_->line);  // a comment's bytes, as check_text checks them
        continue;
      }
      start[k] = text.size();
      line[k] = cursor_->line;
      text.append(l);
      ++k;
    }
    start[n] = text.size();
    cursor_row_ = at + n;
  }
  // The first bad row is the one reported, whichever thread met it.
  std::mutex m;
  size_t bad_row = n;
  std::exception_ptr bad;
  parallel_for(n, n >= 1024 ? threads : 1, [&](size_t lo, size_t hi) {
    ScenarioRows::Tokens tokens;
    for (size_t i = lo; i < hi; ++i) {
      try {
        out[i] = columns_->parse(std::string_view(text).substr(start[i], start[i + 1] - start[i]), line[i],
                                 t ? &t[i] : nullptr, tokens);
      } catch (const InputError&) {
        std::lock_guard<std::mutex> lock(m);
        if (i < bad_row) bad_row = i, bad = std::current_exception();
        return;
      }
    }
  });
  if (bad) {
    std::lock_guard<std::mutex> lock(m_);
    cursor_row_ = rows_;  // re-read from a mark next time
    std::rethrow_exception(bad);
  }
}

}  // namespace portalsim
