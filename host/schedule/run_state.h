// A run's own state files as a resume and a merge read them back: .portalsim/checkpoint.json
// and manifest.json, parsed and every field they use checked for its type, so that a
// damaged or hand-edited file gets a message naming the file and the field, never a JSON
// library's exception.
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace portalsim {

// A checkpoint: an object whose next, positive and negative are whole numbers and whose
// files[] each have a name, bytes and xxh3. Throws OutputError naming `path` (the folder is
// the run's output).
nlohmann::json parse_checkpoint(std::string_view text, const std::string& path);

// A finished run's manifest: an object with the shard's range and count, the classes, the
// spec's count, and outputs[] of plain file names, byte counts and 16-hex-digit hashes.
// Throws InputError naming `path` and the field.
nlohmann::json parse_manifest(std::string_view text, const std::string& path);

// The scenarios in the whole data set a manifest's spec describes (checked by parse_manifest).
uint64_t manifest_total(const nlohmann::json& spec);

}  // namespace portalsim
