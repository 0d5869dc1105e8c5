#include "cli/validate_demo.h"

#include <cstdio>
#include <filesystem>
#include <random>

#include "assets/image_io.h"
#include "base/embedded.h"
#include "base/error.h"
#include "cli/common.h"
#include "schedule/pipeline.h"

namespace portalsim::cli {

namespace {

namespace fs = std::filesystem;

// The "other camera": a 3x3 box blur, gain 0.85 with offset +20, and uniform noise of
// +-8 gray levels from a fixed stream, so the altered images are the same everywhere.
Image alter(const Image& in, uint32_t stream) {
  Image out = in;
  std::mt19937 rng(20260 + stream);
  for (int y = 0; y < in.height; ++y)
    for (int x = 0; x < in.width; ++x)
      for (int c = 0; c < in.channels; ++c) {
        if (c == 3) continue;  // alpha stays
        int sum = 0, n = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx, yy = y + dy;
            if (xx < 0 || yy < 0 || xx >= in.width || yy >= in.height) continue;
            sum += in.at(xx, yy, c);
            ++n;
          }
        const int noise = static_cast<int>(rng() % 17) - 8;
        const int v = static_cast<int>(0.85 * sum / n + 20.5) + noise;
        out.at(x, y, c) = static_cast<uint8_t>(std::clamp(v, 0, 255));
      }
  return out;
}

// Thesis case 2 (scenarios/case2-rod-plate.toml) through `catalogue` (empty: built-in),
// as `generate` makes it; the ARFF table is moved to `table`, the run folder removed.
void generate_set(const std::string& catalogue, uint64_t count, uint64_t seed, int block, const std::string& run_dir,
                  const std::string& table) {
  RunSpec spec;
  parse_spec(embedded::case2_spec, "<case 2 spec>", spec);
  spec.count = count;
  spec.seed = seed;
  spec.formats = {"arff"};
  spec.set_knob_text("block", std::to_string(block), "validate --demo: block");
  spec.validate();
  CommonOptions co;
  co.catalogue = catalogue;
  Session s;
  open_catalogue(s, co);
  validate(spec.settings(), s.catalogue);
  open_backend(s, co);
  PipelineOptions popt;
  popt.progress = false;
  run_pipeline(spec, s.catalogue, s.assets, *s.backend, run_dir, popt);
  std::error_code ec;
  fs::rename(fs::path(run_dir) / "features.arff", table, ec);
  if (ec) throw OutputError(table + ": cannot move into place: " + ec.message());
  fs::remove_all(run_dir, ec);
}

}  // namespace

nlohmann::json make_demo_sets(const std::string& dir, uint64_t count, uint64_t seed, int block) {
  std::error_code ec;
  if (fs::exists(dir, ec)) throw OutputError(dir + ": already exists");
  const fs::path d(dir);
  // The built-in images, as `portalsim catalogue --images` writes them.
  Session built_in;
  open_catalogue(built_in, CommonOptions{});
  const std::string dump = (d / ".catalogue-images").string();
  {
    StagedFolder folder(dump);
    write_catalogue_images(built_in, folder);
    folder.commit();
  }
  // The subjects' MMW views altered, and a catalogue that names them.
  fs::create_directories(d / "images", ec);
  if (ec) throw OutputError((d / "images").string() + ": cannot create: " + ec.message());
  const Catalogue& cat = built_in.catalogue;
  std::vector<std::string> fields(cat.subjects.size());
  for (size_t i = 0; i < cat.subjects.size(); ++i)
    for (size_t k = 0; k < cat.sensors.size(); ++k) {
      const Sensor& view = cat.sensors[k];
      if (!camera_kind(view.camera).feature_views) continue;  // the features' views (and metal) only
      const std::string name = subject_image_name(i, view);
      const Image img = read_image((fs::path(dump) / name).string(), "validate --demo");
      write_image((d / "images" / name).string(), alter(img, static_cast<uint32_t>(i * cat.sensors.size() + k)));
      fields[i] += "images." + view.name + " = \"images/" + name + "\"\n";
    }
  fs::remove_all(dump, ec);
  std::string toml =
      "# portalsim validate --demo: the built-in catalogue with each subject's MMW views\n"
      "# read from images/ (the built-in images blurred, gain-changed and noised).\n";
  const std::string_view text = embedded::default_catalogue;
  size_t subject = 0, at = 0;
  while (at < text.size()) {
    const size_t end = std::min(text.find('\n', at), text.size());
    const std::string_view line = text.substr(at, end - at);
    toml.append(line);
    toml += '\n';
    if (line == "[[subjects]]" && subject < fields.size()) toml += fields[subject++];
    at = end + 1;
  }
  if (subject != fields.size())
    throw std::logic_error("validate --demo: the built-in catalogue has " + std::to_string(subject) +
                           " [[subjects]] lines for " + std::to_string(fields.size()) + " subjects");
  const std::string catalogue = (d / "catalogue.toml").string();
  write_text_atomic(catalogue, toml);

  std::fprintf(stderr, "validate --demo: simulated set, %llu scenarios (seed %llu)\n",
               static_cast<unsigned long long>(count), static_cast<unsigned long long>(seed));
  generate_set("", count, seed, block, (d / ".sim-run").string(), (d / "sim.arff").string());
  std::fprintf(stderr, "validate --demo: \"real\" set through demo/catalogue.toml, %llu scenarios (seed %llu)\n",
               static_cast<unsigned long long>(count), static_cast<unsigned long long>(seed + 1));
  generate_set(catalogue, count, seed + 1, block, (d / ".real-run").string(), (d / "real.arff").string());
  return {{"sim", (d / "sim.arff").string()},
          {"real", (d / "real.arff").string()},
          {"about",
           {{"spec", "thesis case 2 (scenarios/case2-rod-plate.toml): iron rod AND metal plate, balanced"},
            {"scenarios_per_set", count},
            {"block", block},
            {"sim_seed", seed},
            {"real_seed", seed + 1},
            {"real_catalogue", "demo/catalogue.toml"},
            {"real_images", "each subject's MMW views: 3x3 box blur, gain 0.85, offset +20, uniform noise +-8"}}}};
}

}  // namespace portalsim::cli
