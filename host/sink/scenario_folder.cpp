#include "sink/scenario_folder.h"

#include <cstring>

#include "assets/image_io.h"
#include "assets/png_writer.h"
#include "base/error.h"
#include "io/output_file.h"
#include "sink/coco.h"
#include "sink/feature_rows.h"

namespace portalsim {

namespace {
Image gray(const uint8_t* px, int w, int h) {
  Image img(w, h, 1);
  std::memcpy(img.pixels.data(), px, img.pixels.size());
  return img;
}
}  // namespace

void write_scenario_folder(const PathOf& path_of, const BatchOutput& b, size_t i, bool threat, const Palette& palette,
                           const FolderOptions& opt) {
  // The folder is staged (path_of names files in a folder that reaches its final name
  // whole), so each file is written once, in place: no temporary name per file.
  const std::string ext = "." + opt.image_format;
  for (const ViewImages& v : b.views) {
    if (v.empty()) continue;
    const std::string path = path_of(v.name + ext);
    if (opt.image_format != "png") {
      const Image img = gray(v.of(i), v.width, v.height);
      write_image(path, v.palette ? colourise(img, palette) : img, opt.png_level);
    } else if (v.palette) {
      thread_local std::vector<uint8_t> rgb;
      rgb.resize(3 * v.pixels_per_image());
      colourise(v.of(i), v.pixels_per_image(), palette, rgb.data());
      write_png(path, rgb.data(), v.width, v.height, 3, opt.png_level);
    } else {
      write_png(path, v.of(i), v.width, v.height, 1, opt.png_level);
    }
  }
  // Annotations: the instance mask (region numbers, always PNG) and the YOLO boxes.
  for (size_t k = 0; k < b.annotations.size(); ++k) {
    const ViewAnnotations& a = b.annotations[k];
    write_png(path_of("mask_" + b.views[k].name + ".png"), a.mask_of(i), a.width, a.height, 1, opt.png_level);
    io::write_file(path_of(b.views[k].name + ".txt"), yolo_lines(a, i));
  }
  if (!b.metal.empty()) {
    std::string m;
    for (int z = 0; z < b.layout.zones; ++z) {
      if (z) m.push_back(',');
      m += std::to_string(b.metal_of(i)[z]);
    }
    io::write_file(path_of("metal.txt"), m + "\n");
  }
  io::write_file(path_of("threat.txt"), threat ? "yes\n" : "no\n");
  if (!b.features.empty() && !b.metal.empty()) {
    std::string csv = feature_csv_header(b.layout);
    append_feature_row(csv, b, i, threat);
    io::write_file(path_of("features.csv"), csv);
  }
}

}  // namespace portalsim
