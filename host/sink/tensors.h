// Tensor outputs for deep learning: per-scenario arrays, checkpointed and resumed like
// every table.
//   --format npy: each appended batch by batch to <name>.npy (an AppendFile).
//   --format h5:  data.h5.partial is laid out at the start (HDF5 metadata final, closed)
//                 and each batch's rows are written in place at their datasets' offsets,
//                 each dataset's rows hashed for the checkpoint; renamed data.h5 at the end.
//   --format h5 --compress: the tensors are .npy files under .portalsim/tensors/ while the
//                 run goes, and data.h5 is built from them through HDF5 at the end.
// Tensors (N scenarios): upper, lower uint8 NxHxW; ir uint8 NxHxWx3 (RGB through the
// palette) and ir_index uint8 NxHxW (temperature index); metal uint8 Nx19; features
// float32 NxF (image features, when computed); label, subject uint8 N; region_object,
// region_orientation int16 Nx13 (object and drawing index, -1 for none); region_label
// uint8 Nx13 (the rule applied to each region's object on its own); with randomised
// objects only, region_rotation, region_scale float64 Nx13 and region_flip uint8 Nx13 (each
// object's transform, the numbers scenarios.csv records; 0, 1, 0 where a region is empty);
// with annotations, mask_<view> uint8 NxHxW (instance masks: the region number, 0 none).
#pragma once
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "scene/rules.h"
#include "sink/h5_file.h"
#include "sink/sink_kinds.h"
#include "sink/sinks.h"

namespace portalsim {

struct TensorOptions {
  bool h5 = false;                   // build data.h5 at the end; otherwise <name>.npy files
  bool compress = false;             // gzip the HDF5 datasets
  bool images = false;               // the camera views
  bool features = false;             // the image features
  bool scenario = true;              // label, subject, metal, region_* (always in h5)
  bool annotations = false;          // mask_<view>: uint8 NxHxW instance masks
  const ThreatRule* rule = nullptr;  // for region_label; null = every region 0
  nlohmann::json identity;           // the run's identity (version, catalogue, spec): HDF5 attributes
};

// The batch's rows [lo, hi) of one tensor. A view column returns a view of the batch's own
// memory and leaves `dst` alone; any other writes the rows into `dst`, (hi - lo) *
// row_bytes() bytes, and returns them there: Python's arrays are filled in place, with no
// copy through a scratch buffer.
using Fill = std::function<std::string_view(const SceneBatch&, const BatchOutput&, size_t lo, size_t hi, char* dst)>;

// One tensor: its data.h5 dataset and how a batch makes its rows. The tensor sink writes
// these rows to files, and Python (python/) hands them over as NumPy arrays.
struct TensorColumn {
  H5Dataset ds;
  Fill fill;
  bool view = false;  // fill returns the batch's own memory, never `dst`
  // Rows [lo, hi): a view, or made in `scratch` (grown to fit).
  std::string_view rows(const SceneBatch& b, const BatchOutput& o, size_t lo, size_t hi, std::string& scratch) const {
    if (!view && scratch.size() < (hi - lo) * ds.row_bytes()) scratch.resize((hi - lo) * ds.row_bytes());
    return fill(b, o, lo, hi, view ? nullptr : scratch.data());
  }
};

// The tensors `opt` asks for, in data.h5's order.
std::vector<TensorColumn> tensor_columns(const SinkContext& ctx, const TensorOptions& opt);

// The tensors data.h5 holds for a run that asks `r` (generate --format h5; Python's batches).
TensorOptions data_h5_options(const SinkRequest& r);

// `resume` maps a file name (as FileState::name) to its checkpointed state; null when new.
std::unique_ptr<Sink> make_tensor_sink(const SinkContext& ctx, const TensorOptions& opt,
                                       const std::map<std::string, FileState>* resume);

// The .npy header of an array of `shape` with numpy dtype `descr` ("|u1", "<i2", "<f4").
std::string npy_array_header(const std::string& descr, const std::vector<uint64_t>& shape);

}  // namespace portalsim
