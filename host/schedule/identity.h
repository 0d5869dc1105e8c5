// A run's identity (version, catalogue, spec, shard): what a resume, a merge and a
// ranked run compare before they trust what a folder holds.
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sink/append_file.h"

namespace portalsim {

// "spec.seed (1 there, 2 now), spec.count (...)": every entry that differs, one level
// into objects; empty when equal.
std::string differing_keys(const nlohmann::json& was, const nlohmann::json& now, const std::string& prefix = "");

// The manifest.json of a finished run: its identity, count, classes, each output's size
// and XXH3-64, and the images folder when there is one. One function, so that a single
// run, a merge and a ranked run write the same bytes.
nlohmann::json run_manifest(const nlohmann::json& identity, uint64_t count, uint64_t positive, uint64_t negative,
                            const std::vector<FileState>& outputs, bool image_folders);

}  // namespace portalsim
