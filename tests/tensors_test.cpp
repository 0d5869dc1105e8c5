// generate --format h5 and --what images --format npy: the tensors read back with libhdf5
// and compared against the PNG folders, feature table and scenarios.csv of the same spec
// (randomised objects' transforms); byte identity across --batch and --threads; exact
// resume after kill -9.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/wait.h>
#include <xxhash.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "assets/image_io.h"
#include "run_binary.h"
#include "schedule/pipeline.h"
#include "sink/h5_file.h"
#include "support.h"

namespace {

namespace fs = std::filesystem;
using Args = std::vector<std::string>;
using portalsim::test::slurp;

Args plus(Args a, const Args& more) {
  a.insert(a.end(), more.begin(), more.end());
  return a;
}

portalsim::test::Result run(const portalsim::test::TempDir& t, Args args, const fs::path& out) {
  args.insert(args.begin(), "generate");
  args.insert(args.end(), {"--out", out.string(), "--quiet"});
  return portalsim::test::finish(portalsim::test::start_program(t.cap(), portalsim::test::kBinary, args), 300);
}

void ExpectOk(const portalsim::test::Result& r) {
  EXPECT_TRUE(r.exited && r.status == 0) << portalsim::test::describe(r);
}

struct Dataset {
  std::vector<hsize_t> dims;
  std::vector<uint8_t> bytes;  // in the dataset's native type
  size_t count() const {
    size_t n = 1;
    for (hsize_t d : dims) n *= d;
    return n;
  }
};

// Reads a whole dataset of data.h5 with libhdf5 as `type` (a native type).
Dataset read_h5(const fs::path& file, const std::string& name, hid_t type) {
  Dataset d;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_GE(f, 0) << file;
  if (f < 0) return d;
  const hid_t ds = H5Dopen2(f, name.c_str(), H5P_DEFAULT);
  EXPECT_GE(ds, 0) << file << ": no dataset " << name;
  if (ds >= 0) {
    const hid_t space = H5Dget_space(ds);
    d.dims.resize(static_cast<size_t>(H5Sget_simple_extent_ndims(space)));
    H5Sget_simple_extent_dims(space, d.dims.data(), nullptr);
    d.bytes.resize(d.count() * H5Tget_size(type));
    EXPECT_GE(H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, d.bytes.data()), 0) << name;
    H5Sclose(space);
    H5Dclose(ds);
  }
  H5Fclose(f);
  return d;
}

// A scalar variable-length string attribute of the file's root group.
std::string read_h5_string(const fs::path& file, const std::string& name) {
  std::string s;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t a = H5Aopen(f, name.c_str(), H5P_DEFAULT);
  EXPECT_GE(a, 0) << file << ": no attribute " << name;
  if (a >= 0) {
    const hid_t type = H5Aget_type(a);
    char* p = nullptr;
    if (H5Tis_variable_str(type) > 0 && H5Aread(a, type, &p) >= 0 && p) {
      s = p;
      H5free_memory(p);
    }
    H5Tclose(type);
    H5Aclose(a);
  }
  H5Fclose(f);
  return s;
}

// The data bytes of a .npy file (after its header).
std::string npy_data(const fs::path& p) {
  const std::string s = slurp(p);
  EXPECT_GE(s.size(), 10u) << p;
  if (s.size() < 10) return "";
  const size_t header = 10 + static_cast<uint8_t>(s[8]) + 256u * static_cast<uint8_t>(s[9]);
  return s.substr(header);
}

const Args kSpec{"--count", "40", "--seed", "7", "--rule", "gun", "--objects", "1..4", "--what", "both"};

TEST(TensorsH5, RoundTripMatchesImageFoldersAndFeatureTable) {
  portalsim::test::TempDir t;
  const fs::path png = t.w() / "png", h5 = t.w() / "h5";
  ExpectOk(run(t, plus(kSpec, {"--format", "npy"}), png));
  ExpectOk(run(t, plus(kSpec, {"--format", "h5"}), h5));
  const fs::path file = h5 / "data.h5";
  ASSERT_TRUE(fs::exists(file));
  EXPECT_FALSE(fs::exists(h5 / "images")) << "--format h5 writes no image folders";
  EXPECT_FALSE(fs::exists(h5 / ".portalsim")) << "the checkpointed tensors go once data.h5 is built";
  const size_t N = 40;

  // Images: each view against the PNG the same spec wrote.
  for (const std::string view : {"upper", "lower", "ir"}) {
    const Dataset d = read_h5(file, view, H5T_NATIVE_UINT8);
    ASSERT_EQ(d.dims.size(), view == "ir" ? 4u : 3u) << view;
    ASSERT_EQ(d.dims[0], N) << view;
    const size_t per = d.count() / N;
    for (size_t i = 0; i < N; ++i) {
      char name[16];
      std::snprintf(name, sizeof name, "%08zu", i);
      const portalsim::Image img = portalsim::read_image((png / "images" / name / (view + ".png")).string(), view);
      ASSERT_EQ(static_cast<size_t>(img.width), d.dims[2]) << view;
      ASSERT_EQ(static_cast<size_t>(img.height), d.dims[1]) << view;
      ASSERT_EQ(img.pixels.size(), per) << view << " has " << img.channels << " channels in the PNG";
      ASSERT_EQ(std::memcmp(img.pixels.data(), d.bytes.data() + i * per, per), 0) << view << " scenario " << i;
    }
  }
  const Dataset index = read_h5(file, "ir_index", H5T_NATIVE_UINT8);
  ASSERT_EQ(index.dims.size(), 3u);

  // Features, metal zones and labels against features.npy (features, 19 zones, class).
  const std::string table = npy_data(png / "features.npy");
  const Dataset feat = read_h5(file, "features", H5T_NATIVE_FLOAT);
  const Dataset metal = read_h5(file, "metal", H5T_NATIVE_UINT8);
  const Dataset label = read_h5(file, "label", H5T_NATIVE_UINT8);
  ASSERT_EQ(feat.dims.size(), 2u);
  ASSERT_EQ(metal.dims, (std::vector<hsize_t>{N, 19}));
  ASSERT_EQ(label.dims, (std::vector<hsize_t>{N}));
  const size_t F = feat.dims[1], cols = F + 19 + 1;
  ASSERT_EQ(table.size(), N * cols * sizeof(float));
  int positives = 0;
  for (size_t i = 0; i < N; ++i) {
    std::vector<float> row(cols);
    std::memcpy(row.data(), table.data() + i * cols * sizeof(float), cols * sizeof(float));
    EXPECT_EQ(std::memcmp(row.data(), feat.bytes.data() + i * F * sizeof(float), F * sizeof(float)), 0) << i;
    for (size_t z = 0; z < 19; ++z) EXPECT_EQ(row[F + z], metal.bytes[i * 19 + z]) << i << " zone " << z;
    EXPECT_EQ(row[F + 19], label.bytes[i]) << i;
    positives += label.bytes[i];
  }
  EXPECT_GT(positives, 0);
  EXPECT_LT(positives, static_cast<int>(N));

  // Per-region labels: with the rule "gun", region r is a threat exactly when it holds a gun,
  // and a scenario is a threat exactly when one of its regions is.
  const Dataset obj = read_h5(file, "region_object", H5T_NATIVE_INT16);
  const Dataset rl = read_h5(file, "region_label", H5T_NATIVE_UINT8);
  ASSERT_EQ(obj.dims, (std::vector<hsize_t>{N, 13}));
  ASSERT_EQ(rl.dims, (std::vector<hsize_t>{N, 13}));
  const auto* objects = reinterpret_cast<const int16_t*>(obj.bytes.data());
  int gun_regions = 0;
  for (size_t i = 0; i < N; ++i) {
    bool any = false;
    for (size_t r = 0; r < 13; ++r) {
      const bool gun = objects[i * 13 + r] == 0;  // "gun" is the catalogue's first object
      EXPECT_EQ(rl.bytes[i * 13 + r], gun ? 1 : 0) << i << " region " << r;
      any |= gun;
      gun_regions += gun;
    }
    EXPECT_EQ(label.bytes[i], any ? 1 : 0) << i;
  }
  EXPECT_GT(gun_regions, 0);

  // Attributes.
  EXPECT_EQ(read_h5_string(file, "portalsim"), PORTALSIM_VERSION);
  const nlohmann::json manifest = nlohmann::json::parse(slurp(h5 / "manifest.json"));
  EXPECT_EQ(read_h5_string(file, "catalogue_hash"), manifest["catalogue"]["hash"].get<std::string>());
  EXPECT_EQ(nlohmann::json::parse(read_h5_string(file, "spec")), manifest["spec"]);
  EXPECT_EQ(read_h5_string(file, "region_label_rule"), "gun");
}

// The cells of a CSV file with a header line: header name -> column, and the rows.
struct Csv {
  std::map<std::string, size_t> column;
  std::vector<std::vector<std::string>> rows;
};
Csv read_csv(const fs::path& p) {
  Csv c;
  std::istringstream in(slurp(p));
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::string cell;
    std::istringstream l(line);
    while (std::getline(l, cell, ',')) cells.push_back(cell);
    if (!line.empty() && line.back() == ',') cells.push_back("");
    if (header) {
      for (size_t k = 0; k < cells.size(); ++k) c.column[cells[k]] = k;
      header = false;
    } else {
      c.rows.push_back(cells);
    }
  }
  return c;
}

const Args kTransforms{"--rotate", "-40..35", "--scale", "0.7..1.3", "--flip", "on"};

TEST(TensorsH5, TransformsAreWhatScenariosCsvRecords) {
  portalsim::test::TempDir t;
  const Args spec = plus(
      {"--count", "120", "--seed", "12", "--rule", "gun", "--objects", "0..5", "--what", "images", "--format", "h5"},
      kTransforms);
  const fs::path dir = t.w() / "h5";
  ExpectOk(run(t, plus(spec, {"--batch", "50"}), dir));
  const fs::path file = dir / "data.h5";
  const size_t N = 120;
  const Dataset rot = read_h5(file, "region_rotation", H5T_NATIVE_DOUBLE);
  const Dataset scale = read_h5(file, "region_scale", H5T_NATIVE_DOUBLE);
  const Dataset flip = read_h5(file, "region_flip", H5T_NATIVE_UINT8);
  const Dataset obj = read_h5(file, "region_object", H5T_NATIVE_INT16);
  for (const Dataset* d : {&rot, &scale, &flip}) ASSERT_EQ(d->dims, (std::vector<hsize_t>{N, 13}));
  // Stored as float64, as the file holds them (not converted on reading).
  {
    const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    const hid_t ds = H5Dopen2(f, "region_rotation", H5P_DEFAULT);
    const hid_t type = H5Dget_type(ds);
    EXPECT_EQ(H5Tget_class(type), H5T_FLOAT);
    EXPECT_EQ(H5Tget_size(type), 8u);
    H5Tclose(type);
    H5Dclose(ds);
    H5Fclose(f);
  }
  const auto* r = reinterpret_cast<const double*>(rot.bytes.data());
  const auto* s = reinterpret_cast<const double*>(scale.bytes.data());
  const auto* o = reinterpret_cast<const int16_t*>(obj.bytes.data());
  const Csv csv = read_csv(dir / "scenarios.csv");
  ASSERT_EQ(csv.rows.size(), N);
  size_t objects = 0, flipped = 0;
  std::set<double> angles;
  for (size_t i = 0; i < N; ++i)
    for (size_t k = 0; k < 13; ++k) {
      const std::string n = std::to_string(k + 1);
      const std::vector<std::string>& row = csv.rows[i];
      ASSERT_EQ(row.size(), csv.column.size()) << "scenarios.csv row " << i;
      const size_t at = i * 13 + k;
      if (row[csv.column.at("region" + n)] == "none") {
        EXPECT_EQ(o[at], -1) << i << " region " << n;
        EXPECT_EQ(row[csv.column.at("rotation" + n)], "") << i;
        EXPECT_EQ(r[at], 0.0) << i << " region " << n << ": an empty region is the identity";
        EXPECT_EQ(s[at], 1.0) << i << " region " << n;
        EXPECT_EQ(flip.bytes[at], 0) << i << " region " << n;
        continue;
      }
      ++objects;
      // Exactly the recorded doubles: the text reads back as the stored number, bit for bit.
      EXPECT_EQ(std::stod(row[csv.column.at("rotation" + n)]), r[at]) << i << " region " << n;
      EXPECT_EQ(std::stod(row[csv.column.at("scale" + n)]), s[at]) << i << " region " << n;
      EXPECT_EQ(row[csv.column.at("flip" + n)], flip.bytes[at] ? "1" : "0") << i << " region " << n;
      EXPECT_GE(r[at], -40.0);
      EXPECT_LE(r[at], 35.0);
      EXPECT_GE(s[at], 0.7);
      EXPECT_LE(s[at], 1.3);
      flipped += flip.bytes[at];
      angles.insert(r[at]);
    }
  EXPECT_GT(objects, 100u);
  EXPECT_GT(flipped, objects / 4) << "about half the objects are mirrored";
  EXPECT_LT(flipped, objects * 3 / 4);
  EXPECT_GT(angles.size(), objects / 2) << "the angles are drawn per object";

  // Byte-identical for another --batch and --threads, compressed or not; and without
  // randomised objects there are no transform datasets (scenarios.csv has no such columns).
  const fs::path other = t.w() / "other", plain = t.w() / "plain", z = t.w() / "z";
  ExpectOk(run(t, plus(spec, {"--batch", "7", "--threads", "1"}), other));
  EXPECT_TRUE(slurp(file) == slurp(other / "data.h5")) << "--batch 50 and --batch 7 --threads 1 differ";
  ExpectOk(run(t, plus(spec, {"--compress"}), z));
  for (const char* name : {"region_rotation", "region_scale"})
    EXPECT_TRUE(read_h5(z / "data.h5", name, H5T_NATIVE_DOUBLE).bytes == read_h5(file, name, H5T_NATIVE_DOUBLE).bytes)
        << name << " differs under --compress";
  EXPECT_TRUE(read_h5(z / "data.h5", "region_flip", H5T_NATIVE_UINT8).bytes == flip.bytes);
  ExpectOk(run(t, {"--count", "20", "--seed", "12", "--what", "images", "--format", "h5"}, plain));
  const hid_t f = H5Fopen((plain / "data.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  for (const char* name : {"region_rotation", "region_scale", "region_flip"})
    EXPECT_EQ(H5Lexists(f, name, H5P_DEFAULT), 0) << name << " in a run without randomised objects";
  H5Fclose(f);
}

TEST(TensorsNpy, ImageTensorsEqualTheH5Datasets) {
  portalsim::test::TempDir t;
  const Args spec{"--count", "30", "--seed", "8", "--rule", "gun", "--what", "images"};
  const fs::path npy = t.w() / "npy", h5 = t.w() / "h5";
  ExpectOk(run(t, plus(spec, {"--format", "npy"}), npy));
  ExpectOk(run(t, plus(spec, {"--format", "h5"}), h5));
  EXPECT_FALSE(fs::exists(npy / "images")) << "--what images --format npy writes no image folders";
  EXPECT_FALSE(fs::exists(h5 / "data.h5.tmp"));
  for (const std::string name : {"upper", "lower", "ir", "ir_index", "metal", "label", "subject", "region_label"}) {
    const std::string data = npy_data(npy / (name + ".npy"));
    const std::string header = slurp(npy / (name + ".npy")).substr(0, 128);
    EXPECT_NE(header.find("'descr': '|u1'"), std::string::npos) << name << ": not uint8";
    const Dataset d = read_h5(h5 / "data.h5", name, H5T_NATIVE_UINT8);
    ASSERT_EQ(data.size(), d.bytes.size()) << name;
    EXPECT_TRUE(std::memcmp(data.data(), d.bytes.data(), data.size()) == 0) << name;
  }
}

TEST(TensorsH5, ByteIdenticalForAnyBatchAndThreads) {
  portalsim::test::TempDir t;
  const Args spec{"--count", "150", "--seed", "9", "--rule", "gun", "--what", "both", "--format", "h5"};
  for (const bool compress : {false, true}) {
    const Args s = compress ? plus(spec, {"--compress"}) : spec;
    const std::string tag = compress ? "z" : "";
    const fs::path a = t.w() / ("a" + tag), b = t.w() / ("b" + tag), c = t.w() / ("c" + tag);
    ExpectOk(run(t, plus(s, {"--batch", "7", "--threads", "1"}), a));
    ExpectOk(run(t, plus(s, {"--batch", "64", "--threads", "2"}), b));
    ExpectOk(run(t, plus(s, {"--batch", "1000"}), c));
    const std::string ha = slurp(a / "data.h5");
    ASSERT_GT(ha.size(), 150u * 200 * 200);
    EXPECT_TRUE(ha == slurp(b / "data.h5")) << "--batch 7 --threads 1 and --batch 64 --threads 2 differ";
    EXPECT_TRUE(ha == slurp(c / "data.h5")) << "--batch 7 and --batch 1000 differ";
    EXPECT_EQ(slurp(a / "manifest.json"), slurp(b / "manifest.json"));
  }
  EXPECT_LT(fs::file_size(t.w() / "az" / "data.h5"), fs::file_size(t.w() / "a" / "data.h5"))
      << "--compress must make data.h5 smaller";
}

using portalsim::test::checkpoint_next;

// The --count of a spec's arguments (-1 when it has none).
long long count_of(const Args& spec) {
  const auto it = std::find(spec.begin(), spec.end(), "--count");
  return it == spec.end() || it + 1 == spec.end() ? -1 : std::stoll(*(it + 1));
}

// Scenarios of a run killed after its checkpoint passes 300, so that the kill comes mid-run;
// under the sanitizers, whose runs are several times slower, a quarter (the same paths).
const std::string kKilledCount = portalsim::test::kSanitized ? "1000" : "4000";
const std::string kKilledCompressedCount = portalsim::test::kSanitized ? "500" : "1500";

// Runs `spec` to completion in ref/ (unless `reference` is false: a test of a refused
// resume compares nothing with it), and again in killed/ with kill -9 after its checkpoint
// passes 300 scenarios; `after_kill` looks at (and may change) what the kill left; then
// resumes with another batch size. Returns the resumed run's result.
portalsim::test::Result kill_then_resume(portalsim::test::TempDir& t, const Args& spec,
                                         const std::function<void(const fs::path&)>& after_kill,
                                         bool reference = true) {
  const fs::path ref = t.w() / "ref", dir = t.w() / "killed";
  if (reference) ExpectOk(run(t, plus(spec, {"--batch", "500"}), ref));
  const portalsim::test::Killed k = portalsim::test::kill_generate(t, spec, "100", dir, 300);
  EXPECT_TRUE(k.result.signaled) << "the run ended before it could be killed: " << portalsim::test::describe(k.result);
  EXPECT_TRUE(k.next > 0 && k.next < count_of(spec))
      << "the kill must come mid-run; the checkpoint says next " << k.next;
  EXPECT_FALSE(fs::exists(dir / "data.h5")) << "killed mid-run, there is no data.h5 yet";
  after_kill(dir);
  return run(t, plus(spec, {"--batch", "333", "--resume"}), dir);
}

// The resumed run `r` succeeded, and killed/ holds the files of the uninterrupted run in ref/,
// the randomised objects' `transform` dataset a row of 13 regions for each of `count` scenarios.
void expect_resumed_as_whole(const portalsim::test::TempDir& t, const portalsim::test::Result& r,
                             const std::string& count, const char* transform, hid_t type) {
  ExpectOk(r);
  const fs::path ref = t.w() / "ref", dir = t.w() / "killed";
  EXPECT_EQ(read_h5(dir / "data.h5", transform, type).dims, (std::vector<hsize_t>{std::stoull(count), 13}));
  EXPECT_TRUE(slurp(dir / "data.h5") == slurp(ref / "data.h5")) << "the resumed data.h5 differs";
  EXPECT_EQ(slurp(dir / "features.csv"), slurp(ref / "features.csv"));
  EXPECT_EQ(slurp(dir / "manifest.json"), slurp(ref / "manifest.json"));
  EXPECT_FALSE(fs::exists(dir / ".portalsim"));
  EXPECT_FALSE(fs::exists(dir / "data.h5.partial"));
}

TEST(TensorsH5, ResumeAfterKill9IsExact) {
  portalsim::test::TempDir t;
  // With randomised objects: their transform datasets are resumed like every other.
  const Args spec = plus(
      {"--count", kKilledCount, "--seed", "10", "--rule", "gun", "--what", "both", "--format", "h5,csv"}, kTransforms);
  const portalsim::test::Result r = kill_then_resume(t, spec, [](const fs::path& dir) {
    // Laid out before the first row was written: what the kill left is an HDF5 file
    // that HDF5 opens, with every dataset at its full length.
    const fs::path partial = dir / "data.h5.partial";
    ASSERT_TRUE(fs::exists(partial)) << "data.h5 is written in place as data.h5.partial";
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    const hid_t f = H5Fopen(partial.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(f, 0) << "the killed run's data.h5.partial must be a valid HDF5 file";
    const hid_t ds = H5Dopen2(f, "upper", H5P_DEFAULT);
    ASSERT_GE(ds, 0);
    const hid_t space = H5Dget_space(ds);
    hsize_t dims[3] = {0, 0, 0};
    H5Sget_simple_extent_dims(space, dims, nullptr);
    EXPECT_EQ(dims[0], std::stoull(kKilledCount));
    H5Sclose(space);
    H5Dclose(ds);
    H5Fclose(f);
    EXPECT_FALSE(fs::exists(dir / ".portalsim" / "tensors")) << "uncompressed, no .npy copy is kept";
  });
  expect_resumed_as_whole(t, r, kKilledCount, "region_rotation", H5T_NATIVE_DOUBLE);
}

TEST(TensorsH5, CompressedResumeAfterKill9IsExact) {
  portalsim::test::TempDir t;
  const Args spec = plus({"--count", kKilledCompressedCount, "--seed", "10", "--rule", "gun", "--what", "both",
                          "--format", "h5,csv", "--compress"},
                         kTransforms);
  const portalsim::test::Result r = kill_then_resume(t, spec, [](const fs::path& dir) {
    EXPECT_TRUE(fs::exists(dir / ".portalsim" / "tensors")) << "compressed, the batches are .npy files until the end";
    EXPECT_FALSE(fs::exists(dir / "data.h5.partial"));
  });
  expect_resumed_as_whole(t, r, kKilledCompressedCount, "region_flip", H5T_NATIVE_UINT8);
}

// A crash while a finished run renames its files (after the last checkpoint, before the
// manifest), built from a complete run as GenerateResume.CrashWhileFinishingIsResumable
// builds it: the last checkpoint (every row written, the file hashed in order to its end,
// nothing held), data.h5 renamed or not, no manifest. --resume must finish the job. 100 rows
// end inside a chunk.
TEST(TensorsH5, CrashWhileFinishingIsResumable) {
  portalsim::test::TempDir t;
  const Args spec{"--count", "100", "--seed", "4", "--rule", "gun", "--what", "images", "--format", "h5"};
  const fs::path ref = t.w() / "ref";
  ExpectOk(run(t, spec, ref));
  const nlohmann::json m = nlohmann::json::parse(slurp(ref / "manifest.json"));
  nlohmann::json checkpoint;
  checkpoint["identity"] = {
      {"portalsim", m["portalsim"]}, {"catalogue", m["catalogue"]}, {"spec", m["spec"]}, {"shard", m["shard"]}};
  checkpoint["next"] = m["shard"]["end"];
  checkpoint["positive"] = m["classes"]["positive"];
  checkpoint["negative"] = m["classes"]["negative"];
  checkpoint["files"] = nlohmann::json::array();
  for (const nlohmann::json& o : m["outputs"]) {
    const uint64_t hash = std::stoull(o["xxh3_64"].get<std::string>(), nullptr, 16);
    if (o["name"] == "data.h5") {
      checkpoint["files"].push_back({{"name", "data.h5#written"}, {"bytes", o["bytes"]}, {"xxh3", hash}});
      checkpoint["files"].push_back({{"name", "data.h5#held"}, {"bytes", 0}, {"xxh3", XXH3_64bits(nullptr, 0)}});
    } else {
      checkpoint["files"].push_back({{"name", o["name"]}, {"bytes", o["bytes"]}, {"xxh3", hash}});
    }
  }
  for (const bool renamed : {false, true}) {
    SCOPED_TRACE(renamed ? "data.h5 renamed" : "data.h5 not yet renamed");
    const fs::path dir = t.w() / (renamed ? "renamed" : "partial");
    fs::copy(ref, dir, fs::copy_options::recursive);
    fs::create_directory(dir / ".portalsim");
    std::ofstream(dir / ".portalsim" / "checkpoint.json") << checkpoint.dump(1) << "\n";
    fs::remove(dir / "manifest.json");
    if (!renamed) fs::rename(dir / "data.h5", dir / "data.h5.partial");
    ExpectOk(run(t, plus(spec, {"--resume"}), dir));
    EXPECT_TRUE(slurp(dir / "data.h5") == slurp(ref / "data.h5"));
    EXPECT_EQ(slurp(dir / "manifest.json"), slurp(ref / "manifest.json"));
    EXPECT_FALSE(fs::exists(dir / ".portalsim"));
  }
}

TEST(TensorsH5, ResumeRefusesRowsChangedSinceTheCheckpoint) {
  portalsim::test::TempDir t;
  const Args spec{"--count", kKilledCount, "--seed", "10", "--rule", "gun", "--what", "images", "--format", "h5"};
  const portalsim::test::Result r = kill_then_resume(
      t, spec,
      [](const fs::path& dir) {
        // Flip the first written pixel of `upper` (its first chunk is where HDF5 says).
        const fs::path partial = dir / "data.h5.partial";
        H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
        const hid_t f = H5Fopen(partial.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
        ASSERT_GE(f, 0);
        const hid_t ds = H5Dopen2(f, "upper", H5P_DEFAULT);
        const hsize_t origin[3] = {0, 0, 0};
        unsigned filters = 0;
        haddr_t at = HADDR_UNDEF;
        hsize_t size = 0;
        EXPECT_GE(H5Dget_chunk_info_by_coord(ds, origin, &filters, &at, &size), 0);
        H5Dclose(ds);
        H5Fclose(f);
        ASSERT_NE(at, HADDR_UNDEF);
        std::FILE* fp = std::fopen(partial.c_str(), "rb+");
        ASSERT_NE(fp, nullptr);
        std::fseek(fp, static_cast<long>(at), SEEK_SET);
        const int c = std::fgetc(fp);
        std::fseek(fp, static_cast<long>(at), SEEK_SET);
        std::fputc(c ^ 0xff, fp);
        std::fclose(fp);
      },
      false);
  EXPECT_TRUE(r.exited && r.status != 0) << portalsim::test::describe(r);
  EXPECT_NE(r.err.find("data.h5.partial"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("upper"), std::string::npos) << r.err;
}

// The default batch ends where a chunk of data.h5 does (a batch that ends inside one holds
// the other datasets' part of it in memory until the next batch).
TEST(TensorsH5, DefaultBatchEndsWhereAChunkDoes) {
  const portalsim::Catalogue& cat = portalsim::test::catalogue();
  const auto backend = portalsim::make_opencl_backend(cat, portalsim::test::assets(), portalsim::test::runtime());
  for (const bool features : {false, true})
    for (const uint32_t images : {0u, portalsim::kAllViews}) {
      portalsim::Plan plan;
      plan.features = features;
      plan.images = images;
      plan.metal = true;
      const size_t b = portalsim::default_batch(plan, cat, *backend);
      EXPECT_EQ(b % portalsim::kH5ChunkRows, 0u) << "features " << features << ", images " << images;
      EXPECT_GE(b, portalsim::kH5ChunkRows);
      EXPECT_LE(b, 16384u);
    }
}

// A checkpoint whose `next` disagrees with how far data.h5 is written (edited by hand, or
// damaged) is refused naming checkpoint.json and the field, as is one of the wrong type.
TEST(TensorsH5, ResumeRefusesACheckpointWhoseNextDisagrees) {
  const Args spec{"--count", kKilledCount, "--seed", "12", "--rule", "gun", "--what", "images", "--format", "h5"};
  const std::vector<std::pair<std::string, std::function<void(nlohmann::json&)>>> edits{
      {"next says", [](nlohmann::json& c) { c["next"] = c["next"].get<uint64_t>() - 64; }},
      {"next: expected a whole number", [](nlohmann::json& c) { c["next"] = "300"; }},
      {"is not in this run's", [](nlohmann::json& c) { c["next"] = 5000; }},
      {"files[0].bytes: expected a whole number", [](nlohmann::json& c) { c["files"][0]["bytes"] = -1; }},
  };
  for (const auto& [message, edit] : edits) {
    SCOPED_TRACE(message);
    portalsim::test::TempDir t;
    const portalsim::test::Result r = kill_then_resume(
        t, spec,
        [&](const fs::path& dir) {
          const fs::path file = dir / ".portalsim" / "checkpoint.json";
          nlohmann::json c = nlohmann::json::parse(slurp(file));
          edit(c);
          std::ofstream(file) << c.dump(1) << "\n";
        },
        false);
    EXPECT_TRUE(r.exited && r.status != 0) << portalsim::test::describe(r);
    EXPECT_NE(r.err.find("checkpoint.json"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("FileOrderHash"), std::string::npos) << r.err;
  }
}

// data.h5 is allocated whole before the first row: a run whose file could never fit the
// filesystem is refused at once, naming the file, and leaves no folder behind.
TEST(TensorsH5, AFileLargerThanTheFilesystemIsRefusedAtOnce) {
  portalsim::test::TempDir t;
  const fs::path dir = t.w() / "huge";
  const portalsim::test::Result r =
      run(t, {"--count", "1099511627776", "--seed", "1", "--what", "images", "--format", "h5"}, dir);
  EXPECT_TRUE(r.exited && r.status != 0) << portalsim::test::describe(r);
  EXPECT_NE(r.err.find("data.h5.partial: 1099511627776 rows would take"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("more than the whole filesystem holds"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir));
}

TEST(TensorsH5, CompressWithoutH5IsRefusedNamingTheFlag) {
  portalsim::test::TempDir t;
  const portalsim::test::Result r = run(t, {"--count", "5", "--compress"}, t.w() / "x");
  EXPECT_EQ(r.status, 2) << "a usage error";
  portalsim::test::expect_clean_failure(r, t.w() / "x", false, {"--compress"});
}

}  // namespace
