// Annotations as COCO (annotations.json): one image entry per scenario and camera view,
// one annotation per visible object (backend/annotate.h). While the run goes, image and
// annotation records are appended to two checkpointed files under .portalsim/coco/; at
// the end annotations.json is built from them (a temporary name, then a rename), so a
// kill -9 leaves nothing half-written and --resume stays exact.
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sink/sinks.h"

namespace portalsim {

// Where an image of scenario `index` in camera view `view` lives, for COCO's file_name.
struct CocoOptions {
  std::string image_folder_ext;  // "png" or "jpg" when image folders are written, else ""
  std::string tensor_file;       // "data.h5" or "" (then <view>.npy) when images are tensors
  nlohmann::json info;           // COCO's "info" object
};

std::unique_ptr<Sink> make_coco_sink(const SinkContext& ctx, const CocoOptions& opt,
                                     const std::map<std::string, FileState>* resume);

// COCO image and annotation ids: image = index * views + view + 1; annotation = image *
// 16 + region (0-based), unique because a view has at most one object per region.
uint64_t coco_image_id(uint64_t index, size_t views, size_t view);
uint64_t coco_annotation_id(uint64_t image_id, int region);

// COCO's uncompressed RLE of the pixels of `mask` (row-major, width x height) equal to
// `id`, all inside the box (bx, by, bw, bh): run lengths in column-major order, starting
// with a run of others (maybe 0).
std::vector<uint32_t> coco_rle(const uint8_t* mask, int width, int height, uint8_t id, int bx, int by, int bw, int bh);

// One YOLO line per annotation: "class cx cy w h", class = object index (COCO's category
// id - 1), the box's centre and size divided by the image's width and height.
std::string yolo_lines(const ViewAnnotations& a, size_t scenario);

}  // namespace portalsim
