#include "sink/scenario_folder.h"

#include <cstring>

#include "assets/image_io.h"
#include "base/error.h"
#include "sink/coco.h"
#include "sink/feature_rows.h"
#include "sink/staging.h"

namespace portalsim {

namespace {
Image gray(const uint8_t* px, int w, int h) {
  Image img(w, h, 1);
  std::memcpy(img.pixels.data(), px, img.pixels.size());
  return img;
}

void write(const std::string& path, const Image& img) {
  try {
    write_image(path, img);
  } catch (const std::exception& e) {
    throw OutputError(e.what());
  }
}
}  // namespace

void write_scenario_folder(const PathOf& path_of, const BatchOutput& b, size_t i, bool threat, const Palette& palette,
                           const FolderOptions& opt) {
  const std::string ext = "." + opt.image_format;
  for (const ViewImages& v : b.views) {
    if (v.empty()) continue;
    const Image img = gray(v.of(i), v.width, v.height);
    write(path_of(v.name + ext), v.palette ? colourise(img, palette) : img);
  }
  // Annotations: the instance mask (region numbers, always PNG) and the YOLO boxes.
  for (size_t k = 0; k < b.annotations.size(); ++k) {
    const ViewAnnotations& a = b.annotations[k];
    write(path_of("mask_" + b.views[k].name + ".png"), gray(a.mask_of(i), a.width, a.height));
    write_text_atomic(path_of(b.views[k].name + ".txt"), yolo_lines(a, i));
  }
  if (!b.metal.empty()) {
    std::string m;
    for (int z = 0; z < kZones; ++z) {
      if (z) m.push_back(',');
      m += std::to_string(b.metal_of(i)[z]);
    }
    write_text_atomic(path_of("metal.txt"), m + "\n");
  }
  write_text_atomic(path_of("threat.txt"), threat ? "yes\n" : "no\n");
  if (!b.features.empty() && !b.metal.empty()) {
    std::string csv = feature_csv_header(b.layout);
    append_feature_row(csv, b, i, threat);
    write_text_atomic(path_of("features.csv"), csv);
  }
}

}  // namespace portalsim
