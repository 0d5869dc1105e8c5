// generate --annotations: annotations.json checked against COCO's published format
// (cocodataset.org/#format-data) by this test's own reader, the RLE decoded back onto the
// mask images, YOLO lines checked against the boxes, masks in data.h5, byte identity
// across --batch and --threads, exact resume after kill -9, and what merge does.
#include "sink/coco.h"

#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "assets/image_io.h"
#include "run_binary.h"
#include "scene/philox.h"

namespace {

namespace fs = std::filesystem;
using Args = std::vector<std::string>;
using nlohmann::json;
using portalsim::test::slurp;

Args plus(Args a, const Args& more) {
  a.insert(a.end(), more.begin(), more.end());
  return a;
}

portalsim::test::Result run(const portalsim::test::TempDir& t, Args args, const fs::path& out,
                            const std::string& command = "generate") {
  args.insert(args.begin(), command);
  args.insert(args.end(), {"--out", out.string(), "--quiet"});
  return portalsim::test::finish(portalsim::test::start_program(t.cap(), portalsim::test::kBinary, args), 300);
}

void ExpectOk(const portalsim::test::Result& r) {
  EXPECT_TRUE(r.exited && r.status == 0) << portalsim::test::describe(r);
}

// The mask decoded from COCO's uncompressed RLE (column-major run lengths, first run 0s).
std::vector<uint8_t> decode_rle(const json& seg, int& w, int& h) {
  h = seg.at("size")[0].get<int>();
  w = seg.at("size")[1].get<int>();
  std::vector<uint8_t> m(static_cast<size_t>(w) * h, 0);
  size_t at = 0;
  bool on = false;
  for (const json& c : seg.at("counts")) {
    const auto n = c.get<uint64_t>();
    for (uint64_t k = 0; k < n && at < m.size(); ++k, ++at)
      if (on) m[(at % h) * w + at / h] = 1;
    on = !on;
  }
  EXPECT_EQ(at, m.size()) << "the RLE's counts must sum to height * width";
  return m;
}

// Checks a COCO file's structure as the format defines it; returns it.
json check_coco(const fs::path& file) {
  const json c = json::parse(slurp(file));
  for (const char* k : {"info", "images", "annotations", "categories"}) EXPECT_TRUE(c.contains(k)) << k;
  std::set<uint64_t> cat_ids, image_ids, ann_ids;
  for (const json& cat : c.at("categories")) {
    EXPECT_TRUE(cat.at("id").is_number_integer() && cat.at("name").is_string() && cat.at("supercategory").is_string());
    cat_ids.insert(cat.at("id").get<uint64_t>());
  }
  EXPECT_EQ(*cat_ids.begin(), 1u) << "category ids start at 1 (0 reads as background)";
  EXPECT_EQ(*cat_ids.rbegin(), cat_ids.size()) << "category ids 1..n";
  for (const json& im : c.at("images")) {
    EXPECT_TRUE(im.at("id").is_number_integer() && im.at("file_name").is_string() &&
                im.at("width").is_number_integer() && im.at("height").is_number_integer());
    EXPECT_TRUE(image_ids.insert(im.at("id").get<uint64_t>()).second) << "image ids are unique";
  }
  for (const json& a : c.at("annotations")) {
    EXPECT_TRUE(ann_ids.insert(a.at("id").get<uint64_t>()).second) << "annotation ids are unique";
    EXPECT_TRUE(image_ids.count(a.at("image_id").get<uint64_t>()));
    EXPECT_TRUE(cat_ids.count(a.at("category_id").get<uint64_t>()));
    EXPECT_TRUE(a.at("area").is_number()) << "area must be a number (BlenderProc #48)";
    EXPECT_EQ(a.at("iscrowd"), 0);
    EXPECT_TRUE(a.at("bbox").is_array() && a.at("bbox").size() == 4);
    EXPECT_TRUE(a.at("segmentation").at("counts").is_array() && a.at("segmentation").at("size").size() == 2);
  }
  return c;
}

Args annotated(const std::string& count, const std::string& what = "images") {
  return {"--count", count, "--seed", "4", "--objects", "2..8", "--what", what, "--jitter", "40", "--annotations"};
}
const Args kSpec = annotated("30");

TEST(Coco, ValidAndAgreesWithMasksAndYolo) {
  portalsim::test::TempDir t;
  const fs::path out = t.w() / "set", h5 = t.w() / "h5";
  ExpectOk(run(t, kSpec, out));
  ExpectOk(run(t, plus(kSpec, {"--format", "h5"}), h5));
  const json c = check_coco(out / "annotations.json");
  EXPECT_EQ(c.at("images").size(), 30u * 3) << "one image entry per scenario and view";
  std::map<uint64_t, json> images;
  for (const json& im : c.at("images")) images[im.at("id").get<uint64_t>()] = im;
  std::map<std::string, std::vector<json>> per_file;
  std::map<std::string, portalsim::Image> masks;  // each read once: an image has several annotations
  size_t annotations = 0;
  for (const json& a : c.at("annotations")) {
    const json& im = images.at(a.at("image_id").get<uint64_t>());
    const fs::path png = out / im.at("file_name").get<std::string>();
    ASSERT_TRUE(fs::exists(png)) << png;
    const std::string view = im.at("view"), folder = png.parent_path().string();
    const std::string mask_path = folder + "/mask_" + view + ".png";
    auto known = masks.find(mask_path);
    if (known == masks.end()) known = masks.emplace(mask_path, portalsim::read_image(mask_path, "mask")).first;
    const portalsim::Image& mask = known->second;
    int w = 0, h = 0;
    const std::vector<uint8_t> m = decode_rle(a.at("segmentation"), w, h);
    ASSERT_EQ(w, mask.width);
    ASSERT_EQ(h, mask.height);
    const int region = a.at("region").get<int>();
    int x0 = w, y0 = h, x1 = -1, y1 = -1, area = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const bool on = m[static_cast<size_t>(y) * w + x];
        ASSERT_EQ(on, mask.at(x, y) == region) << "RLE and mask image differ at " << x << "," << y;
        if (!on) continue;
        ++area;
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
      }
    EXPECT_EQ(a.at("area").get<int>(), area);
    EXPECT_GT(area, 0) << "an object with no visible pixel has no annotation";
    EXPECT_EQ(a.at("bbox"), json({x0, y0, x1 - x0 + 1, y1 - y0 + 1}));
    EXPECT_TRUE(a.at("orientation").is_string() && a.at("dx").is_number() && a.at("dy").is_number());
    per_file[folder + "/" + view + ".txt"].push_back(a);
    ++annotations;
  }
  EXPECT_GT(annotations, 100u);
  // Every region number in a mask has its annotation.
  for (const auto& [id, im] : images) {
    const fs::path png = out / im.at("file_name").get<std::string>();
    const std::string view = im.at("view");
    const portalsim::Image mask = portalsim::read_image(png.parent_path().string() + "/mask_" + view + ".png", "mask");
    std::set<int> regions;
    for (uint8_t v : mask.pixels)
      if (v) regions.insert(v);
    EXPECT_EQ(regions.size(), per_file[png.parent_path().string() + "/" + view + ".txt"].size()) << png;
  }
  // YOLO: "class cx cy w h", normalised, one line per annotation in COCO's order.
  for (const auto& [id, im] : images) {
    const fs::path png = out / im.at("file_name").get<std::string>();
    const std::string txt = png.parent_path().string() + "/" + im.at("view").get<std::string>() + ".txt";
    std::istringstream in(slurp(txt));
    const double W = im.at("width"), H = im.at("height");
    for (const json& a : per_file[txt]) {
      int cls = -1;
      double cx, cy, bw, bh;
      ASSERT_TRUE(in >> cls >> cx >> cy >> bw >> bh) << txt;
      EXPECT_EQ(cls, a.at("category_id").get<int>() - 1);
      const json& b = a.at("bbox");
      EXPECT_NEAR(cx, (b.at(0).get<double>() + b.at(2).get<double>() / 2) / W, 1e-6);
      EXPECT_NEAR(cy, (b.at(1).get<double>() + b.at(3).get<double>() / 2) / H, 1e-6);
      EXPECT_NEAR(bw, b.at(2).get<double>() / W, 1e-6);
      EXPECT_NEAR(bh, b.at(3).get<double>() / H, 1e-6);
      for (double v : {cx, cy, bw, bh}) EXPECT_TRUE(v > 0 && v <= 1) << txt;
    }
    std::string rest;
    EXPECT_FALSE(in >> rest) << txt << ": more lines than annotations";
  }
  // data.h5's mask datasets hold the same masks; its COCO file names point into it.
  const json ch = check_coco(h5 / "annotations.json");
  EXPECT_EQ(ch.at("annotations"), c.at("annotations"));
  EXPECT_EQ(ch.at("images").at(0).at("file_name"), "data.h5#upper/0");
  for (const std::string view : {"upper", "lower", "ir"}) {
    const hid_t f = H5Fopen((h5 / "data.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    const hid_t ds = H5Dopen2(f, ("mask_" + view).c_str(), H5P_DEFAULT);
    ASSERT_GE(ds, 0) << "mask_" << view;
    const hid_t space = H5Dget_space(ds);
    hsize_t dims[3];
    ASSERT_EQ(H5Sget_simple_extent_ndims(space), 3);
    H5Sget_simple_extent_dims(space, dims, nullptr);
    std::vector<uint8_t> all(dims[0] * dims[1] * dims[2]);
    EXPECT_GE(H5Dread(ds, H5T_NATIVE_UINT8, H5S_ALL, H5S_ALL, H5P_DEFAULT, all.data()), 0);
    H5Sclose(space);
    H5Dclose(ds);
    H5Fclose(f);
    ASSERT_EQ(dims[0], 30u);
    for (size_t i = 0; i < 30; ++i) {
      const portalsim::Image m =
          portalsim::read_image((out / "images" / (std::string(i < 10 ? "0000000" : "000000") + std::to_string(i)) /
                                 ("mask_" + view + ".png"))
                                    .string(),
                                "mask");
      EXPECT_TRUE(std::memcmp(m.pixels.data(), all.data() + i * dims[1] * dims[2], m.pixels.size()) == 0)
          << view << " " << i;
    }
  }
}

// The RLE visits only the object's box; it must equal a plain run-length pass over every
// pixel, whatever the box touches (the view's edges, full columns, one pixel).
TEST(Coco, RleOfTheBoxEqualsAPlainPassOverTheImage) {
  int cases = 0;
  for (uint64_t k = 0; k < 4000; ++k) {
    const portalsim::Philox4 r = portalsim::draw(3, k, 0, 0);
    const int W = 1 + static_cast<int>(r[0] % 9), H = 1 + static_cast<int>(r[1] % 9);
    const int bx = static_cast<int>(r[2] % W), by = static_cast<int>(r[3] % H);
    const portalsim::Philox4 q = portalsim::draw(3, k, 1, 0);
    const int bw = 1 + static_cast<int>(q[0] % (W - bx)), bh = 1 + static_cast<int>(q[1] % (H - by));
    std::vector<uint8_t> mask(static_cast<size_t>(W) * H, 0);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const uint32_t u = portalsim::draw(3, k, 2, static_cast<uint32_t>(y * W + x))[0];
        const bool in_box = x >= bx && x < bx + bw && y >= by && y < by + bh;
        mask[static_cast<size_t>(y) * W + x] = in_box ? (u % 3 ? 5 : 2) : (u % 2 ? 7 : 0);  // id 5 only in the box
      }
    std::vector<uint32_t> plain;
    bool on = false;
    uint32_t run = 0;
    for (int x = 0; x < W; ++x)
      for (int y = 0; y < H; ++y) {
        if ((mask[static_cast<size_t>(y) * W + x] == 5) != on) {
          plain.push_back(run);
          run = 0;
          on = !on;
        }
        ++run;
      }
    plain.push_back(run);
    ASSERT_EQ(portalsim::coco_rle(mask.data(), W, H, 5, bx, by, bw, bh), plain)
        << W << "x" << H << " box " << bx << "," << by << " " << bw << "x" << bh;
    ++cases;
  }
  EXPECT_EQ(cases, 4000);
}

TEST(Coco, ByteIdenticalForAnyBatchAndThreads) {
  portalsim::test::TempDir t;
  const Args s = plus(annotated("90"), {"--format", "h5", "--placement", "bilinear"});
  const fs::path a = t.w() / "a", b = t.w() / "b";
  ExpectOk(run(t, plus(s, {"--batch", "7", "--threads", "1"}), a));
  ExpectOk(run(t, plus(s, {"--batch", "64", "--threads", "2"}), b));
  EXPECT_TRUE(slurp(a / "annotations.json") == slurp(b / "annotations.json"));
  EXPECT_TRUE(slurp(a / "data.h5") == slurp(b / "data.h5"));
  EXPECT_EQ(slurp(a / "manifest.json"), slurp(b / "manifest.json"));
  EXPECT_NE(slurp(a / "manifest.json").find("annotations.json"), std::string::npos);
}

using portalsim::test::checkpoint_next;

// Every file under `dir`, by path relative to it (folders excluded).
std::vector<std::string> files_under(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) out.push_back(fs::relative(e.path(), dir).string());
  std::sort(out.begin(), out.end());
  return out;
}

// The same files with the same bytes under the annotated image folders of both runs; a
// file missing from either fails (slurp would read it as "").
void ExpectSameImageFolders(const fs::path& got, const fs::path& want, size_t scenarios) {
  const std::vector<std::string> names = files_under(want / "images");
  ASSERT_EQ(files_under(got / "images"), names);
  std::set<std::string> folders;
  for (const std::string& n : names) {
    EXPECT_TRUE(slurp(got / "images" / n) == slurp(want / "images" / n)) << n;
    folders.insert(fs::path(n).parent_path().string());
  }
  EXPECT_EQ(folders.size(), scenarios) << "one folder per scenario";
}

TEST(Coco, ResumeAfterKill9IsExact) {
  portalsim::test::TempDir t;
  // Killed after 200: under the sanitizers, whose runs are several times slower, half the run.
  const int count = portalsim::test::kSanitized ? 400 : 800;
  for (const std::string format : {"h5", "csv"}) {  // tensors, and image folders (--what both)
    const Args spec = plus(annotated(std::to_string(count), "both"), {"--format", format});
    const fs::path ref = t.w() / ("ref" + format), dir = t.w() / ("killed" + format);
    ExpectOk(run(t, plus(spec, {"--batch", "500"}), ref));
    const portalsim::test::Killed k = portalsim::test::kill_generate(t, spec, "50", dir, 200);
    ASSERT_TRUE(k.result.signaled) << "the run ended before it could be killed: "
                                   << portalsim::test::describe(k.result);
    ASSERT_TRUE(k.next > 0 && k.next < count) << "the kill must come mid-run; the checkpoint says next " << k.next;
    ASSERT_FALSE(fs::exists(dir / "annotations.json")) << "killed mid-run, there is no annotations.json yet";
    ExpectOk(run(t, plus(spec, {"--batch", "333", "--resume"}), dir));
    EXPECT_TRUE(slurp(dir / "annotations.json") == slurp(ref / "annotations.json")) << format;
    EXPECT_EQ(slurp(dir / "manifest.json"), slurp(ref / "manifest.json")) << format;
    if (format == "h5") {
      EXPECT_TRUE(slurp(dir / "data.h5") == slurp(ref / "data.h5"));
    } else {
      ExpectSameImageFolders(dir, ref, count);
    }
  }
}

TEST(Coco, MergeRefusesAnnotationsNamingThem) {
  portalsim::test::TempDir t;
  const Args s = annotated("20");
  ExpectOk(run(t, plus(s, {"--shard", "0/2"}), t.w() / "p0"));
  ExpectOk(run(t, plus(s, {"--shard", "1/2"}), t.w() / "p1"));
  const portalsim::test::Result r = portalsim::test::finish(
      portalsim::test::start_program(
          t.cap(), portalsim::test::kBinary,
          {"merge", (t.w() / "p0").string(), (t.w() / "p1").string(), "--out", (t.w() / "m").string()}),
      120);
  EXPECT_TRUE(r.exited && r.status != 0) << portalsim::test::describe(r);
  EXPECT_NE(r.err.find("annotations.json"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(t.w() / "m" / "manifest.json"));
}

TEST(Coco, AnnotationsWithoutImagesAreRefused) {
  portalsim::test::TempDir t;
  const portalsim::test::Result r = run(t, {"--count", "5", "--annotations"}, t.w() / "x");
  EXPECT_EQ(r.status, 2) << "a usage error";
  portalsim::test::expect_clean_failure(r, t.w() / "x", false, {"--annotations"});
}

TEST(Coco, SpecFileKeyTurnsThemOnAndIsCheckedThere) {
  portalsim::test::TempDir t;
  const fs::path good = t.w() / "good.toml", bad = t.w() / "bad.toml";
  portalsim::test::spit(good, "count = 4\nwhat = \"images\"\nannotations = true\n");
  portalsim::test::spit(bad, "count = 4\nannotations = true\n");
  ExpectOk(run(t, {"--spec", good.string()}, t.w() / "a"));
  EXPECT_TRUE(fs::exists(t.w() / "a" / "annotations.json"));
  const portalsim::test::Result r = run(t, {"--spec", bad.string()}, t.w() / "b");
  EXPECT_TRUE(r.exited && r.status == 3) << "a bad spec file exits 3: " << portalsim::test::describe(r);
  EXPECT_NE(r.err.find(bad.string() + ":2"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("needs images"), std::string::npos) << r.err;
}

}  // namespace

namespace {

// Randomised objects: each annotation carries its object's rotation, scale and flip, the
// values scenarios.csv records for its scenario and region; boxes still agree with masks
// (ValidAndAgreesWithMasksAndYolo's checks run in check_coco and below).
TEST(Coco, RandomisedObjectsCarryTheirDraws) {
  portalsim::test::TempDir t;
  const fs::path out = t.w() / "set";
  ExpectOk(run(t, plus(annotated("16"), {"--rotate", "40", "--scale", "0.8..1.2", "--flip", "on"}), out));
  const json c = check_coco(out / "annotations.json");
  std::map<uint64_t, uint64_t> scenario_of;
  for (const json& im : c.at("images")) scenario_of[im.at("id").get<uint64_t>()] = im.at("scenario").get<uint64_t>();
  // scenarios.csv: index, subject, region1..13, rotation1..13, scale1..13, flip1..13, label.
  std::map<uint64_t, std::vector<std::string>> rows;
  std::istringstream in(slurp(out / "scenarios.csv"));
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
    rows[std::stoull(f.at(0))] = f;
  }
  ASSERT_EQ(rows.size(), 16u);
  size_t checked = 0, turned = 0, mirrored = 0;
  for (const json& a : c.at("annotations")) {
    const std::vector<std::string>& f = rows.at(scenario_of.at(a.at("image_id").get<uint64_t>()));
    const int r = a.at("region").get<int>();  // 1-based
    EXPECT_EQ(a.at("rotation").get<double>(), std::stod(f.at(1 + 13 + r)));
    EXPECT_EQ(a.at("scale").get<double>(), std::stod(f.at(1 + 26 + r)));
    EXPECT_EQ(a.at("flip").get<bool>(), f.at(1 + 39 + r) == "1");
    EXPECT_TRUE(a.at("rotation").get<double>() >= -40 && a.at("rotation").get<double>() <= 40);
    turned += a.at("rotation").get<double>() != 0;
    mirrored += a.at("flip").get<bool>();
    ++checked;
  }
  EXPECT_GT(checked, 40u);
  EXPECT_EQ(turned, checked);
  EXPECT_GT(mirrored, 5u);
  EXPECT_LT(mirrored, checked - 5);
}

}  // namespace
