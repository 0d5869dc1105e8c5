// portalsim features: scenario folders (simulated or real captures) to a feature table,
// the thesis's generate.java (appendix D.3).
#include <cstdio>
#include <filesystem>

#include "base/error.h"
#include "cli/commands.h"
#include "cli/common.h"
#include "cli/features_table.h"
#include "sink/folder_reader.h"
#include "sink/sinks.h"

namespace portalsim::cli {

namespace {
struct FeaturesOptions {
  CommonOptions common;
  std::vector<std::string> folders;
  std::string out, format;
  int block = 10;
  std::string grid;
};

int features(FeaturesOptions& o) {
  if (!o.grid.empty()) o.block = block_for_grid(o.grid, o.common.catalogue);
  std::string format = o.format;
  if (format.empty()) {
    format = std::filesystem::path(o.out).extension().string();
    if (!format.empty()) format.erase(0, 1);
  }
  const FeaturesCount n = write_features(o.folders, o.out, format, o.block, o.common.catalogue);
  std::printf("%s: %zu rows (%zu positive, %zu negative) from %zu folders\n", o.out.c_str(), n.rows, n.positive,
              n.rows - n.positive, n.rows);
  return 0;
}
}  // namespace

FeaturesCount write_features(const std::vector<std::string>& folder_args, const std::string& out_name,
                             const std::string& format, int block, const std::string& catalogue) {
  namespace fs = std::filesystem;
  Session s;
  CommonOptions common;
  common.catalogue = catalogue;
  open_catalogue(s, common);
  Plan plan;
  plan.model.block = block;
  validate(plan, s.catalogue);
  if (format != "arff" && format != "csv" && format != "npy")
    throw InputError("--out: \"" + out_name + "\": name it .arff, .csv or .npy, or give --format");
  const fs::path out(out_name);
  if (fs::exists(out)) throw OutputError(out_name + ": already exists; choose a new file name");
  const std::vector<std::string> folders = find_scenario_folders(folder_args, s.catalogue);

  BatchOutput rows;
  rows.layout = FeatureLayout::of(s.catalogue, block);
  SceneBatch labels(s.catalogue.region_count());
  const size_t chunk = 1024;
  SinkContext ctx;
  ctx.dir = out.parent_path().empty() ? "." : out.parent_path().string();
  ctx.cat = &s.catalogue;
  ctx.assets = &s.assets;
  ctx.layout = rows.layout;
  ctx.rows = folders.size();
  ctx.threads = 1;
  std::error_code ec;
  if (!fs::is_directory(ctx.dir, ec)) throw OutputError(ctx.dir + ": no such folder for --out");
  std::unique_ptr<Sink> sink;
  size_t positive = 0;
  try {
    sink = make_table_sink(format, ctx, nullptr, out.filename().string());  // writes the header: may fail too
    for (size_t first = 0; first < folders.size(); first += chunk) {
      const size_t n = std::min(chunk, folders.size() - first);
      rows.n = n;
      rows.features.assign(n * rows.layout.image_features(), 0.0f);
      rows.metal.assign(n * s.catalogue.zones, 0);
      labels.clear();
      labels.first_index = first;
      for (size_t i = 0; i < n; ++i) {
        Scenario sc;
        sc.label = read_scenario_folder(folders[first + i], s.catalogue, rows, i) ? 1 : 0;
        positive += sc.label;
        labels.push(sc);
      }
      sink->write(labels, rows);
    }
    sink->finish();
  } catch (...) {
    sink.reset();
    fs::remove(fs::path(ctx.dir) / (out.filename().string() + ".partial"), ec);
    if (format == "npy") fs::remove(fs::path(ctx.dir) / (out.stem().string() + ".columns.txt"), ec);
    throw;
  }
  return {folders.size(), positive};
}

int block_for_grid(const std::string& grid, const std::string& catalogue) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(grid.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') || w < 1 || h < 1)
    throw InputError("--grid: \"" + grid + "\" is not WxH (for example 5x5)");
  Session s;
  CommonOptions common;
  common.catalogue = catalogue;
  open_catalogue(s, common);
  const int block = FeatureLayout::block_for_grid(s.catalogue, w, h);
  if (block == 0)
    throw InputError("--grid: no square block cuts every pooled view into " + grid + " blocks; use --block");
  return block;
}

std::function<int()> add_features(CLI::App& app) {
  auto o = std::make_shared<FeaturesOptions>();
  CLI::App* sub =
      app.add_subcommand("features", "turn scenario folders (simulated or real captures) into a feature table");
  sub->add_option("folders", o->folders, "scenario folders, or folders holding them")->required();
  sub->add_option("--out", o->out, "output table: FILE.arff, FILE.csv or FILE.npy")->required();
  sub->add_option("--format", o->format, "arff, csv or npy (default: from --out's extension)");
  auto* block = sub->add_option("--block", o->block, "block side for the averaged features (default 10)");
  sub->add_option("--grid", o->grid, "WxH blocks per view instead of --block (5x5: the thesis's grid)")
      ->excludes(block);
  sub->add_option("--catalogue", o->common.catalogue, "catalogue TOML file (its region rectangles are used)");
  return [o] { return features(*o); };
}

}  // namespace portalsim::cli
