#include "sink/sink_kinds.h"

#include <algorithm>

#include "base/error.h"

namespace portalsim {

// Each kind is declared in its sink's file; a new kind is one line here, in the order a
// run opens them.
#define PORTALSIM_SINK_KINDS(X) \
  X(scenario_list_kind)         \
  X(feature_tables_kind)        \
  X(image_folders_kind)         \
  X(data_h5_kind)               \
  X(npy_tensors_kind)           \
  X(coco_kind)

#define PORTALSIM_DECLARE_KIND(k) extern const SinkKind k;
PORTALSIM_SINK_KINDS(PORTALSIM_DECLARE_KIND)
#undef PORTALSIM_DECLARE_KIND

const std::vector<const SinkKind*>& sink_kinds() {
#define PORTALSIM_KIND_ADDRESS(k) &k,
  static const std::vector<const SinkKind*> kinds{PORTALSIM_SINK_KINDS(PORTALSIM_KIND_ADDRESS)};
#undef PORTALSIM_KIND_ADDRESS
  return kinds;
}

bool SinkRequest::has_format(std::string_view f) const {
  return std::find(formats.begin(), formats.end(), f) != formats.end();
}

const FileState* SinkStart::state(const std::string& dir, const std::string& file) const {
  if (!saved) return nullptr;
  const auto it = saved->find(file);
  if (it == saved->end()) throw OutputError(dir + "/.portalsim/checkpoint.json: no state for " + file);
  return &it->second;
}

const SinkKind* sink_kind_of(std::string_view file) {
  for (const SinkKind* k : sink_kinds())
    if (k->writes(file)) return k;
  return nullptr;
}

Sinks open_sinks(const SinkRequest& req, const SinkContext& ctx, const SinkStart& start) {
  Sinks sinks;
  for (const SinkKind* k : sink_kinds())
    if (k->wanted(req)) k->open(req, ctx, start, sinks);
  return sinks;
}

std::vector<std::string> format_values() {
  std::vector<std::string> out;
  for (const SinkKind* k : sink_kinds())
    for (std::string_view f : k->formats)
      if (std::find(out.begin(), out.end(), f) == out.end()) out.emplace_back(f);
  return out;
}

std::string format_help() {
  std::string out;
  for (const SinkKind* k : sink_kinds())
    if (!k->format_help.empty()) out += (out.empty() ? "" : "; ") + std::string(k->format_help);
  return out + " (default arff)";
}

}  // namespace portalsim
