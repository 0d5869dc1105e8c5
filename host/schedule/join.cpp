#include "schedule/join.h"

#include <fcntl.h>
#include <unistd.h>
#include <xxhash.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

#include "base/error.h"
#include "base/sizes.h"
#include "io/input_file.h"
#include "schedule/dataset_card.h"
#include "schedule/identity.h"
#include "schedule/run_state.h"
#include "sink/append_file.h"
#include "sink/h5_file.h"
#include "sink/output_folder.h"
#include "sink/sink_kinds.h"
#include "sink/staging.h"
#include "sink/tensors.h"

namespace portalsim {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string read_whole(const fs::path& p) { return io::read_file(p.string(), "part file", io::kMaxTextBytes); }

// The keys a part's manifest shares with every other part of the same data set.
json shared_identity(const json& manifest) {
  json id = json::object();
  for (const char* k : {"portalsim", "catalogue", "spec"}) id[k] = manifest.value(k, json());
  return id;
}

// How merge joins a manifest's file: its sink kind says (sink/sink_kinds.h).
JoinAs join_of(const std::string& name, const std::string& part) {
  const SinkKind* k = sink_kind_of(name);
  if (!k || !k->join)
    throw InputError(part + "/manifest.json: outputs: \"" + name + "\" is no output portalsim knows how to join");
  const JoinAs how = k->join(name);
  if (how == JoinAs::refused)
    throw InputError(part + "/manifest.json: outputs: " + name + " (generate " + std::string(k->flag) +
                     "): " + std::string(k->refusal) +
                     "; make the data set in one run (--batch and --threads never change it)");
  return how;
}

// The header of a text table: its first line (CSV), or everything through "@data" (ARFF).
size_t text_header_bytes(const std::string& path, std::string& header) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot read");
  std::string head(1 << 20, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(in.gcount()));
  size_t end;
  if (path.ends_with(".arff")) {
    end = head.find("\n@data\n");
    if (end != std::string::npos) end += 7;
  } else {
    end = head.find('\n');
    if (end != std::string::npos) end += 1;
  }
  if (end == std::string::npos) throw InputError(path + ": has no header portalsim wrote");
  header = head.substr(0, end);
  return end;
}

struct NpyHeader {
  size_t bytes = 0;
  std::string descr;
  std::vector<uint64_t> shape;
};

NpyHeader read_npy_header(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char pre[10];
  if (!in.read(pre, sizeof pre) || std::memcmp(pre, "\x93NUMPY\x01\x00", 8) != 0)
    throw InputError(path + ": not a version 1.0 .npy file");
  NpyHeader h;
  const size_t len = static_cast<unsigned char>(pre[8]) + 256u * static_cast<unsigned char>(pre[9]);
  std::string dict(len, '\0');
  if (!in.read(dict.data(), static_cast<std::streamsize>(len))) throw InputError(path + ": truncated .npy header");
  h.bytes = 10 + len;
  const size_t d = dict.find("'descr': '"), s = dict.find("'shape': (");
  if (d == std::string::npos || s == std::string::npos) throw InputError(path + ": .npy header without descr or shape");
  h.descr = dict.substr(d + 10, dict.find('\'', d + 10) - (d + 10));
  const size_t close = dict.find(')', s);
  std::istringstream dims(dict.substr(s + 10, close - (s + 10)));
  std::string item;
  while (std::getline(dims, item, ',')) {
    const size_t a = item.find_first_not_of(' ');
    if (a == std::string::npos) continue;
    try {
      h.shape.push_back(std::stoull(item.substr(a)));
    } catch (const std::exception&) {
      throw InputError(path + ": .npy shape \"" + item + "\" is not a number");
    }
  }
  if (h.shape.empty()) throw InputError(path + ": .npy header has an empty shape");
  return h;
}

int open_or_throw(const std::string& path, int flags) {
  const int fd = ::open(path.c_str(), flags | O_CLOEXEC, 0644);
  if (fd < 0) throw OutputError(path + ": cannot open: " + std::strerror(errno));
  return fd;
}

void pwrite_all(int fd, const char* p, size_t n, uint64_t off, const std::string& path) {
  while (n > 0) {
    const ssize_t w = ::pwrite(fd, p, n, static_cast<off_t>(off));
    if (w < 0) {
      if (errno == EINTR) continue;
      throw OutputError(path + ": write failed: " + std::strerror(errno));
    }
    p += w;
    n -= static_cast<size_t>(w);
    off += static_cast<uint64_t>(w);
  }
}

// A part's file must be what its manifest recorded: {"bytes": N, "xxh3_64": "hex"}.
void check_recorded(const std::string& path, const json& recorded, uint64_t bytes, uint64_t hash) {
  if (recorded.value("bytes", uint64_t(0)) != bytes || recorded.value("xxh3_64", std::string()) != xxh3_hex(hash))
    throw InputError(path + ": its bytes are not those its manifest.json records (changed or damaged since)");
}

// A file rank 0 creates at its final size with its header; every rank then writes its
// rows at their offsets.
void create_sized(const std::string& path, const std::string& header, uint64_t bytes) {
  const int fd = open_or_throw(path, O_WRONLY | O_CREAT | O_TRUNC);
  const bool ok = ::ftruncate(fd, static_cast<off_t>(bytes)) == 0;
  const int err = errno;
  if (!ok) {
    ::close(fd);
    throw OutputError(path + ": cannot size to " + std::to_string(bytes) + " bytes: " + std::strerror(err));
  }
  pwrite_all(fd, header.data(), header.size(), 0, path);
  ::close(fd);
}

class RangeWriter {
 public:
  explicit RangeWriter(const std::string& path) : path_(path), fd_(open_or_throw(path, O_WRONLY)) {}
  ~RangeWriter() {
    if (fd_ >= 0) ::close(fd_);
  }
  void write(const char* p, size_t n, uint64_t off) { pwrite_all(fd_, p, n, off, path_); }
  void finish() {
    if (::fsync(fd_) != 0) throw OutputError(path_ + ": fsync failed: " + std::strerror(errno));
    ::close(fd_);
    fd_ = -1;
  }

 private:
  std::string path_;
  int fd_;
};

using Xxh3 = std::unique_ptr<XXH3_state_t, decltype(&XXH3_freeState)>;

Xxh3 new_xxh3() {
  Xxh3 h(XXH3_createState(), XXH3_freeState);
  if (!h) throw std::bad_alloc();
  XXH3_64bits_reset(h.get());
  return h;
}

// Copies bytes [from, from + bytes) of `src` to `dst` at `to`, checking that the whole of
// `src` is what its manifest says (size and XXH3-64); `written`, when given, takes the
// bytes copied (a rank that writes a whole file in order hashes it on the way).
void copy_range(const std::string& src, const json& recorded, uint64_t from, uint64_t bytes, RangeWriter& dst,
                uint64_t to, XXH3_state_t* written) {
  std::ifstream in(src, std::ios::binary);
  const Xxh3 h = new_xxh3();
  std::vector<char> buf(kIoPieceBytes);
  uint64_t at = 0;
  const uint64_t end = from + bytes;
  while (at < end) {
    const size_t n = static_cast<size_t>(std::min<uint64_t>(end - at, buf.size()));
    if (!in.read(buf.data(), static_cast<std::streamsize>(n)))
      throw InputError(src + ": shorter than its manifest says");
    XXH3_64bits_update(h.get(), buf.data(), n);
    const uint64_t skip = at < from ? std::min<uint64_t>(from - at, n) : 0;
    if (skip < n) {
      dst.write(buf.data() + skip, n - skip, to + (at + skip - from));
      if (written) XXH3_64bits_update(written, buf.data() + skip, n - skip);
    }
    at += n;
  }
  check_recorded(src, recorded, end, XXH3_64bits_digest(h.get()));
}

// dst/<name> from src/<name>, each file hard-linked (copied across filesystems), through
// a staging name so a half-linked folder never has its final name.
void link_folder(const fs::path& src, const fs::path& dst) {
  const fs::path tmp = dst.string() + ".tmp";
  std::error_code ec;
  if (fs::is_symlink(src, ec) || !fs::is_directory(src, ec))
    throw InputError(src.string() + ": not a scenario folder portalsim wrote");
  fs::remove_all(tmp, ec);
  fs::create_directory(tmp, ec);
  if (ec) throw OutputError(tmp.string() + ": cannot create: " + ec.message());
  for (const auto& e : fs::directory_iterator(src)) {
    if (e.is_symlink() || !e.is_regular_file()) throw InputError(e.path().string() + ": not a file portalsim wrote");
    const fs::path to = tmp / e.path().filename();
    fs::create_hard_link(e.path(), to, ec);
    if (ec) {
      ec.clear();
      fs::copy_file(e.path(), to, ec);
      if (ec) throw OutputError(to.string() + ": cannot copy: " + ec.message());
    }
  }
  fs::remove_all(dst, ec);
  fs::rename(tmp, dst, ec);
  if (ec) throw OutputError(dst.string() + ": cannot move into place: " + ec.message());
}

}  // namespace

std::vector<Part> read_parts(const std::vector<std::string>& dirs) {
  if (dirs.empty()) throw InputError("merge: no parts given");
  std::vector<Part> parts;
  for (const std::string& d : dirs) {
    const fs::path m = fs::path(d) / "manifest.json";
    std::error_code ec;
    if (!fs::is_regular_file(m, ec))
      throw InputError(d + ": no manifest.json: not a finished run (finish it with generate --resume first)");
    Part p;
    p.dir = d;
    p.manifest = parse_manifest(io::read_text_file(m.string(), "manifest", io::Bom::refuse), m.string());
    p.begin = p.manifest["shard"]["begin"].get<uint64_t>();
    p.end = p.manifest["shard"]["end"].get<uint64_t>();
    parts.push_back(std::move(p));
  }
  const json id = shared_identity(parts[0].manifest);
  std::vector<std::string> names;
  for (const json& o : parts[0].manifest["outputs"]) names.push_back(o.at("name").get<std::string>());
  for (const Part& p : parts) {
    if (const std::string diff = differing_keys(shared_identity(p.manifest), id, {"here", "in the first"});
        !diff.empty())
      throw InputError("part " + p.dir + " differs from the first part " + parts[0].dir + " in " + diff);
    std::vector<std::string> n;
    for (const json& o : p.manifest["outputs"]) n.push_back(o.at("name").get<std::string>());
    if (n != names) throw InputError(p.dir + ": holds other outputs than " + parts[0].dir);
    if (p.manifest.contains("images") != parts[0].manifest.contains("images"))
      throw InputError(p.dir + ": images folder present in one part and not the other (" + parts[0].dir + ")");
  }
  std::stable_sort(parts.begin(), parts.end(),
                   [](const Part& a, const Part& b) { return a.begin != b.begin ? a.begin < b.begin : a.end < b.end; });
  const uint64_t total = manifest_total(id["spec"]);
  uint64_t next = 0;
  for (size_t k = 0; k < parts.size(); ++k) {
    const Part& p = parts[k];
    if (p.begin > next)
      throw InputError("merge: no part holds scenarios [" + std::to_string(next) + ", " + std::to_string(p.begin) +
                       ") of " + std::to_string(total));
    if (p.begin < next)
      throw InputError("merge: " + p.dir + " and " + parts[k - 1].dir + " both hold scenarios [" +
                       std::to_string(p.begin) + ", " + std::to_string(std::min(next, p.end)) + ")");
    next = p.end;
  }
  if (next != total)
    throw InputError("merge: no part holds scenarios [" + std::to_string(next) + ", " + std::to_string(total) +
                     ") of " + std::to_string(total));
  // Parts that hold no scenarios (more shards than scenarios) add nothing.
  std::vector<Part> kept;
  for (Part& p : parts)
    if (p.end > p.begin || kept.empty()) kept.push_back(std::move(p));
  return kept;
}

namespace {

// Which parts (and which outputs' hashes) a rank handles: every size-th from its rank.
struct Share {
  int me = 0, size = 1;
  bool mine(size_t k) const { return static_cast<int>(k % static_cast<size_t>(size)) == me; }
};

struct JoinedPiece {
  std::string src;
  json recorded;                         // the part manifest's entry for the file
  uint64_t from = 0, bytes = 0, to = 0;  // for h5: rows [from, from + bytes) of `to`'s first row
};
struct JoinedOutput {
  std::string name, path, header;
  uint64_t bytes = 0;
  int dataset = -1;                 // h5.datasets index, for a dataset of data.h5
  std::vector<JoinedPiece> pieces;  // one per part
};

// The plan, the same on every rank: per output, the whole header and where each part's
// rows go. data.h5 is joined as one .npy per dataset, then built by rank 0.
struct JoinPlan {
  std::vector<JoinedOutput> outputs;
  std::vector<std::string> dataset_paths;
  H5Layout h5;
  bool has_h5 = false;
};

json recorded_entry(const Part& part, const std::string& name) {
  for (const json& o : part.manifest["outputs"])
    if (o.value("name", "") == name) return o;
  throw InputError(part.dir + "/manifest.json: no entry for " + name);
}

// A part's data.h5 must be what its manifest records before HDF5 opens it.
void check_part_h5s(const std::vector<Part>& parts, Share share) {
  for (size_t k = 0; k < parts.size(); ++k)
    if (share.mine(k))
      for (const json& o : parts[k].manifest["outputs"])
        if (o["name"] == "data.h5") {
          io::check_regular_file((fs::path(parts[k].dir) / "data.h5").string(), "part's data.h5", SIZE_MAX);
          const FileState f = hash_file(parts[k].dir, "data.h5");
          check_recorded((fs::path(parts[k].dir) / "data.h5").string(), o, f.bytes, f.xxh3);
        }
}

// data.h5's datasets, each joined as one .npy under `work`: every part's layout must be the
// first's, and its rows what its manifest says.
void plan_h5(JoinPlan& plan, const std::vector<Part>& parts, const std::string& name, const json& identity,
             const fs::path& work) {
  const uint64_t total = parts.back().end;
  H5Layout& h5 = plan.h5;
  plan.has_h5 = true;
  std::vector<H5Layout> layouts;
  for (const Part& p : parts) layouts.push_back(read_h5_layout((fs::path(p.dir) / name).string()));
  h5 = layouts[0];
  for (size_t k = 0; k < parts.size(); ++k) {
    H5Layout& l = layouts[k];
    const std::string path = (fs::path(parts[k].dir) / name).string();
    if (l.rows != parts[k].end - parts[k].begin)
      throw InputError(path + ": holds " + std::to_string(l.rows) + " rows; its manifest says " +
                       std::to_string(parts[k].end - parts[k].begin));
    bool same = l.compress == h5.compress && l.datasets.size() == h5.datasets.size() &&
                l.attributes.size() == h5.attributes.size();
    for (size_t d = 0; same && d < l.datasets.size(); ++d)
      same = l.datasets[d].name == h5.datasets[d].name && l.datasets[d].type == h5.datasets[d].type &&
             l.datasets[d].dims == h5.datasets[d].dims && l.datasets[d].columns == h5.datasets[d].columns;
    for (size_t a = 0; same && a < l.attributes.size(); ++a)
      same = l.attributes[a].name == h5.attributes[a].name &&
             (l.attributes[a].name == "identity" || l.attributes[a].values == h5.attributes[a].values);
    if (!same) throw InputError(path + ": its datasets or attributes differ from " + parts[0].dir + "/data.h5");
  }
  h5.rows = total;
  for (H5Attribute& a : h5.attributes)
    if (a.name == "identity") a.values = {identity.dump()};
  for (size_t di = 0; di < h5.datasets.size(); ++di) {
    const H5Dataset& d = h5.datasets[di];
    JoinedOutput t;
    t.name = "data.h5:" + d.name;
    t.dataset = static_cast<int>(di);
    t.path = (work / (d.name + ".npy")).string();
    std::vector<uint64_t> shape{total};
    shape.insert(shape.end(), d.dims.begin(), d.dims.end());
    t.header = npy_array_header(npy_descr(d.type), shape);
    t.bytes = t.header.size() + total * d.row_bytes();
    for (const Part& p : parts)
      t.pieces.push_back(JoinedPiece{(fs::path(p.dir) / name).string(), json(), 0, p.end - p.begin,
                                     t.header.size() + p.begin * d.row_bytes()});
    plan.dataset_paths.push_back(t.path);
    plan.outputs.push_back(std::move(t));
  }
}

// A text or .npy output, joined under out as name.partial: each part's file must be the size
// its manifest records, and its header (text) or shape (.npy) the first part's.
JoinedOutput plan_file(const std::vector<Part>& parts, const std::string& name, JoinAs kind, const fs::path& out) {
  const uint64_t total = parts.back().end;
  JoinedOutput t;
  t.name = name;
  t.path = (out / (name + ".partial")).string();
  std::vector<uint64_t> dims;
  for (size_t k = 0; k < parts.size(); ++k) {
    const std::string src = (fs::path(parts[k].dir) / name).string();
    std::error_code ec;
    const uint64_t size = fs::file_size(src, ec);
    if (ec) throw InputError(src + ": cannot read: " + ec.message());
    const json recorded = recorded_entry(parts[k], name);
    if (const uint64_t want = recorded.value("bytes", uint64_t(0)); size != want)
      throw InputError(src + ": " + std::to_string(size) + " bytes; its manifest.json records " + std::to_string(want) +
                       " (changed or damaged since)");
    std::string header;
    if (kind == JoinAs::text) {
      const size_t h = text_header_bytes(src, header);
      if (k == 0) t.header = header;
      if (header != t.header) throw InputError(src + ": its header differs from " + parts[0].dir + "/" + name);
      t.pieces.push_back(JoinedPiece{src, recorded, h, size - h, 0});
    } else {
      const NpyHeader h = read_npy_header(src);
      std::vector<uint64_t> rest(h.shape.begin() + 1, h.shape.end());
      if (k == 0) {
        dims = rest;
        std::vector<uint64_t> shape{total};
        shape.insert(shape.end(), rest.begin(), rest.end());
        t.header = npy_array_header(h.descr, shape);
      }
      if (rest != dims || h.shape[0] != parts[k].end - parts[k].begin ||
          npy_array_header(h.descr, h.shape).size() != h.bytes)
        throw InputError(src + ": its shape does not fit the part's " + std::to_string(parts[k].end - parts[k].begin) +
                         " rows or " + parts[0].dir + "/" + name);
      t.pieces.push_back(JoinedPiece{src, recorded, h.bytes, size - h.bytes, 0});
    }
  }
  uint64_t to = t.header.size();
  for (JoinedPiece& p : t.pieces) {
    p.to = to;
    to += p.bytes;
  }
  t.bytes = to;
  return t;
}

// Rank 0's share: every file at its size with its header, and the small files beside the
// outputs (an npy table's column names), which are the same in every part.
void create_outputs(const JoinPlan& plan, const std::vector<Part>& parts, const fs::path& out, const fs::path& work) {
  const json& first = parts[0].manifest;
  std::error_code ec;
  if (plan.has_h5) {
    fs::create_directories(work, ec);
    if (ec) throw OutputError(work.string() + ": cannot create: " + ec.message());
  }
  if (first.contains("images")) {
    fs::create_directories(out / "images", ec);
    if (ec) throw OutputError((out / "images").string() + ": cannot create: " + ec.message());
  }
  for (const JoinedOutput& t : plan.outputs) create_sized(t.path, t.header, t.bytes);
  for (const auto& e : fs::directory_iterator(parts[0].dir)) {
    const std::string n = e.path().filename().string();
    if (!e.is_regular_file() || n == "manifest.json" || n == "README.md" || n == "croissant.json" ||
        n.starts_with(kStateDir))
      continue;  // each part's own; the whole gets its own card
    bool listed = false;
    for (const json& o : first["outputs"]) listed = listed || o["name"] == n;
    if (listed) continue;
    const std::string text = read_whole(e.path());
    for (const Part& p : parts)
      if (read_whole(fs::path(p.dir) / n) != text)
        throw InputError(p.dir + "/" + n + ": differs from " + parts[0].dir + "/" + n);
    write_text_atomic((out / n).string(), text);
  }
}

// This rank's parts of every output and of the images; `written` gets the (bytes, XXH3-64)
// of each output a lone rank wrote whole, hashed as it went.
void write_pieces(const JoinPlan& plan, const std::vector<Part>& parts, Share share, const fs::path& out,
                  std::map<std::string, std::pair<uint64_t, uint64_t>>& written) {
  std::vector<char> buf;
  for (const JoinedOutput& t : plan.outputs) {
    RangeWriter w(t.path);
    // Alone, this rank writes every byte in order: hash as it goes, saving a read.
    Xxh3 whole(nullptr, XXH3_freeState);
    if (share.size == 1 && t.dataset < 0) {
      whole = new_xxh3();
      XXH3_64bits_update(whole.get(), t.header.data(), t.header.size());
    }
    for (size_t k = 0; k < parts.size(); ++k) {
      if (!share.mine(k)) continue;
      const JoinedPiece& p = t.pieces[k];
      if (t.dataset >= 0) {
        const H5Dataset& d = plan.h5.datasets[static_cast<size_t>(t.dataset)];
        const uint64_t row = d.row_bytes(), block = std::max<uint64_t>(1, kIoPieceBytes / std::max<uint64_t>(1, row));
        for (uint64_t r = 0; r < p.bytes; r += block) {
          const uint64_t n = std::min(block, p.bytes - r);
          buf.resize(static_cast<size_t>(n * row));
          read_h5_rows(p.src, d, r, n, buf.data());
          w.write(buf.data(), buf.size(), p.to + r * row);
        }
      } else {
        copy_range(p.src, p.recorded, p.from, p.bytes, w, p.to, whole.get());
      }
    }
    w.finish();
    if (whole) written[t.name] = {t.bytes, XXH3_64bits_digest(whole.get())};
  }
  if (parts[0].manifest.contains("images"))
    for (size_t k = 0; k < parts.size(); ++k) {
      if (!share.mine(k)) continue;
      for (uint64_t i = parts[k].begin; i < parts[k].end; ++i) {
        const std::string name = image_folder_name(i);
        link_folder(fs::path(parts[k].dir) / "images" / name, out / "images" / name);
      }
    }
}

// Each output's bytes and hash for the manifest, the outputs shared out among the ranks.
std::vector<FileState> output_states(const std::vector<std::string>& names,
                                     const std::map<std::string, std::pair<uint64_t, uint64_t>>& written,
                                     const std::string& out_dir, Ranks& ranks, Share share) {
  json hashes = json::object(), mine_h = json::object();
  ranks.together([&] {
    for (size_t i = 0; i < names.size(); ++i) {
      if (!share.mine(i)) continue;
      if (const auto it = written.find(names[i]); it != written.end()) {
        mine_h[names[i]] = {it->second.first, it->second.second};
        continue;
      }
      const std::string file = names[i] == "data.h5" ? names[i] : names[i] + ".partial";
      const FileState s = hash_file(out_dir, file);
      mine_h[names[i]] = {s.bytes, s.xxh3};
    }
  });
  for (const std::string& g : ranks.all_gather(mine_h.dump())) {
    const json theirs = json::parse(g);
    for (const auto& [k, v] : theirs.items()) hashes[k] = v;
  }
  std::vector<FileState> states;
  for (const std::string& n : names)
    states.push_back(FileState{n, hashes.at(n)[0].get<uint64_t>(), hashes.at(n)[1].get<uint64_t>()});
  return states;
}

}  // namespace

JoinResult join_parts(const std::vector<Part>& parts, const std::string& out_dir, Ranks& ranks) {
  const fs::path out(out_dir), work = out / kStateDir / "join";
  const Share share{ranks.rank(), ranks.size()};
  const json& first = parts[0].manifest;
  const uint64_t total = parts.back().end;

  JoinResult res;
  res.count = total;
  for (const Part& p : parts) {
    res.positive += p.manifest.at("classes").at("positive").get<uint64_t>();
    res.negative += p.manifest.at("classes").at("negative").get<uint64_t>();
  }
  json identity = shared_identity(first);
  identity["shard"] = {{"index", 0}, {"count", 1}, {"begin", 0}, {"end", total}};

  std::map<std::string, std::pair<uint64_t, uint64_t>> written;  // output -> (bytes, XXH3-64) hashed while written
  JoinPlan plan;
  ranks.together([&] { check_part_h5s(parts, share); });
  ranks.together([&] {
    for (const json& o : first["outputs"]) {
      const std::string name = o.at("name").get<std::string>();
      const JoinAs kind = join_of(name, parts[0].dir);
      if (kind == JoinAs::h5)
        plan_h5(plan, parts, name, identity, work);
      else
        plan.outputs.push_back(plan_file(parts, name, kind, out));
    }
  });

  // Rank 0 makes every file at its size with its header; then each rank writes its parts.
  ranks.together([&] {
    if (share.me == 0) create_outputs(plan, parts, out, work);
  });
  ranks.together([&] { write_pieces(plan, parts, share, out, written); });

  // data.h5 from the joined datasets (one writer: HDF5 without MPI is serial).
  ranks.together([&] {
    if (share.me != 0 || !plan.has_h5) return;
    write_h5(out_dir, plan.h5, plan.dataset_paths);
    std::error_code ec;
    fs::remove_all(work, ec);
  });

  std::vector<std::string> names;
  for (const json& o : first["outputs"]) names.push_back(o["name"]);
  const std::vector<FileState> states = output_states(names, written, out_dir, ranks, share);
  for (const FileState& f : states) res.bytes += f.bytes;

  ranks.together([&] {
    if (share.me != 0) return;
    for (const std::string& n : names) {
      if (n == "data.h5") continue;
      std::error_code ec;
      fs::rename(out / (n + ".partial"), out / n, ec);
      if (ec) throw OutputError((out / n).string() + ": cannot move into place: " + ec.message());
    }
    const json manifest = run_manifest(identity, total, res.positive, res.negative, states, first.contains("images"));
    write_dataset_card(out_dir, manifest);
    write_text_atomic((out / "manifest.json").string(), manifest.dump(2) + "\n");
  });
  return res;
}

}  // namespace portalsim
