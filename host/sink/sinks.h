// Data-set sinks: each takes batches in index order and appends them to its outputs.
//   features.arff  WEKA's format (thesis 5.3, appendix D.4)
//   features.csv   the same rows with a header
//   features.npy   float32 matrix (features, the metal zones, class 1/0), names in features.columns.txt
//   scenarios.csv  index, subject, region1..region13, label: re-runnable with --scenarios;
//                  with randomised objects also rotation1..13, scale1..13, flip1..13
//   images/<index>/ the folder `simulate` writes, per scenario
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "assets/png_writer.h"
#include "assets/procedural.h"
#include "backend/backend.h"
#include "sink/append_file.h"

namespace portalsim {

class Sink {
 public:
  virtual ~Sink() = default;
  virtual void write(const SceneBatch& scenes, const BatchOutput& out) = 0;
  // The files as they stand (for checkpoints and the manifest).
  virtual std::vector<FileState> files() const = 0;
  virtual void finish() = 0;
};

struct SinkContext {
  std::string dir;
  const Catalogue* cat = nullptr;
  const AssetSet* assets = nullptr;
  FeatureLayout layout;
  uint64_t rows = 0;  // rows the finished table will hold (the npy header needs it)
  uint64_t done = 0;  // resuming: rows written before, by the checkpoint's `next`
  unsigned threads = 1;
  ModelSettings model;  // the model's knobs (scenarios.csv records each object's randomised transform)
  std::string image_format = "png";
  int png_level = kDefaultPngLevel;            // image folders' PNGs (png_writer.h)
  Palette palette = procedural::ir_palette();  // the IR index as RGB (Plan::palette)
};

// format: arff, csv or npy; the file is ctx.dir/name (default "features.<format>"; an npy
// table's column names go beside it in <stem>.columns.txt). `resume` is the file's
// checkpointed state, or null.
std::unique_ptr<Sink> make_table_sink(const std::string& format, const SinkContext& ctx, const FileState* resume,
                                      const std::string& name = "");
std::unique_ptr<Sink> make_scenario_list_sink(const SinkContext& ctx, const FileState* resume);
// Writes images/<index>/ folders; on resume, folders from `resume_from` on are removed first.
std::unique_ptr<Sink> make_image_sink(const SinkContext& ctx, bool resume, uint64_t resume_from);

std::string image_folder_name(uint64_t index);
std::string arff_header(const FeatureLayout& layout);
std::string npy_header(uint64_t rows, size_t columns);

}  // namespace portalsim
