// One scenario's outputs as a folder, the layout of thesis appendix D.2 step 7:
// upper.png, lower.png (MMW), ir.png (IR through the palette), metal.txt, threat.txt,
// features.csv; with annotations, mask_<view>.png (instance mask) and <view>.txt (YOLO).
#pragma once
#include <functional>
#include <string>

#include "assets/assets.h"
#include "assets/png_writer.h"
#include "backend/backend.h"

namespace portalsim {

struct FolderOptions {
  std::string image_format = "png";  // png or jpg
  int png_level = kDefaultPngLevel;  // the PNGs' deflate level (png_writer.h); masks are PNG with jpg too
};

// Where each file goes: a staged folder's path(), or a plain folder being built under a
// temporary name.
using PathOf = std::function<std::string(const std::string& name)>;

// Writes scenario i of `b`, each file at path_of(its name).
void write_scenario_folder(const PathOf& path_of, const BatchOutput& b, size_t i, bool threat, const Palette& palette,
                           const FolderOptions& opt);

}  // namespace portalsim
