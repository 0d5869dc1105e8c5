// A run's identity (version, catalogue, spec, shard): what a resume, a merge and a
// ranked run compare before they trust what a folder holds.
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sink/append_file.h"

namespace portalsim {

// What the two sides of a comparison are called in a message: "in the folder", "now".
struct Sides {
  std::string was, now;
};

// "spec.seed: 1 in the folder, 2 now; spec.count: ...": every entry that differs, one level
// into objects, each value followed by its side's name; empty when equal.
std::string differing_keys(const nlohmann::json& was, const nlohmann::json& now, const Sides& sides,
                           const std::string& prefix = "");

// The manifest.json of a finished run: its identity, count, classes, each output's size
// and XXH3-64, and the images folder when there is one. One function, so that a single
// run, a merge and a ranked run write the same bytes.
nlohmann::json run_manifest(const nlohmann::json& identity, uint64_t count, uint64_t positive, uint64_t negative,
                            const std::vector<FileState>& outputs, bool image_folders);

}  // namespace portalsim
