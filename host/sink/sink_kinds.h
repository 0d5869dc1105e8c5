// The kinds of output `generate` writes, registered in one list (sink_kinds.cpp). Each kind
// is declared in its sink's own file and says how a run asks for it, which sinks it opens,
// which files are its own, how `merge` joins them and what the dataset card says of them;
// the pipeline, the spec's checks, --format's help, merge and the card read it from here.
#pragma once
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "scene/rules.h"
#include "sink/sinks.h"

namespace portalsim {

// What a run asks of its outputs, in the sinks' terms (the pipeline fills it from the run's
// spec and plan).
struct SinkRequest {
  std::vector<std::string> formats;                            // --format, in the order given
  bool features = false, images = false, annotations = false;  // what the plan computes
  bool image_tensors = false;                                  // images go to data.h5 or <view>.npy instead of folders
  bool npy_image_tensors = false;  // images go to <view>.npy (--format npy with --what images)
  bool compress = false;           // gzip data.h5's datasets
  std::string image_format = "png";
  const ThreatRule* rule = nullptr;  // the run's rule (per-region labels), or null
  nlohmann::json identity;           // the run's identity (version, catalogue, spec)
  bool has_format(std::string_view f) const;
};

// Where the sinks start: a new folder, or a resumed one's checkpointed files.
struct SinkStart {
  const std::map<std::string, FileState>* saved = nullptr;  // resuming: each file's checkpointed state
  uint64_t first = 0;                                       // the first scenario this run writes
  // A file's checkpointed state; null for a new run. Throws OutputError when resuming
  // and the checkpoint lacks it.
  const FileState* state(const std::string& dir, const std::string& file) const;
};

// How `merge` joins a kind's file from shards.
enum class JoinAs {
  text,     // a header, then rows in index order (CSV: its first line; ARFF: through @data)
  npy,      // a .npy header, then rows
  h5,       // data.h5: each dataset's rows
  refused,  // merge cannot join it (SinkKind::refusal says why)
};

using Sinks = std::vector<std::unique_ptr<Sink>>;

struct SinkKind {
  std::string_view name;  // what it writes, for messages: "annotations.json"
  std::string_view flag;  // how a run asks for it, for messages: "--annotations"
  // The --format values that ask for it, and their words in --format's help.
  std::vector<std::string_view> formats;
  std::string_view format_help;
  bool (*wanted)(const SinkRequest&) = nullptr;
  // Appends the sinks it opens for a run that wants it.
  void (*open)(const SinkRequest&, const SinkContext&, const SinkStart&, Sinks&) = nullptr;
  bool (*writes)(std::string_view file) = nullptr;  // is a manifest's file this kind's?
  JoinAs (*join)(std::string_view file) = nullptr;
  std::string_view refusal;  // JoinAs::refused: why merge cannot join it yet
  // The dataset card's words for its file, given the portal's region and zone counts;
  // "" leaves the file to the card (a tensor is described by its name).
  std::string (*meaning)(std::string_view file, int regions, int zones) = nullptr;
};

// Every kind, in the order a run opens them (the manifest lists files in that order).
const std::vector<const SinkKind*>& sink_kinds();
// The kind whose file `file` is (the first in that order), or null.
const SinkKind* sink_kind_of(std::string_view file);
// The sinks a run asks for, in order.
Sinks open_sinks(const SinkRequest& req, const SinkContext& ctx, const SinkStart& start);
// Every --format value, in the kinds' order; and --format's help, from the kinds'.
std::vector<std::string> format_values();
std::string format_help();

}  // namespace portalsim
