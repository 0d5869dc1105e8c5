// Reading scenario folders back (thesis 5.6.1, the conversion algorithm, and appendix
// D.3's generate.java): upper and lower MMW images, metal.txt and threat.txt in, one
// feature row out. Works on folders that simulate or generate wrote, and on real
// captures laid out the same way.
#pragma once
#include <string>
#include <vector>

#include "backend/backend.h"

namespace portalsim {

// The scenario folders under each path, in order: a path that holds the first pooled
// view's image (upper.*) itself is one folder; otherwise its sub-folders are searched
// (sorted by name), recursively.
std::vector<std::string> find_scenario_folders(const std::vector<std::string>& paths, const Catalogue& cat);

// Reads folder `dir` into row i of `out` (features and metal) and returns its label: the
// pooled views' images, named as their sensors (upper, lower), pooled by pool_images.
// Images of another size are rejected. Throws InputError naming the file and line.
bool read_scenario_folder(const std::string& dir, const Catalogue& cat, BatchOutput& out, size_t i);

// metal.txt's text: one line of `zones` zone values 0..200 (the catalogue's zones). `source`
// names it in errors.
std::vector<uint8_t> parse_metal_text(std::string_view text, const std::string& source, int zones);
// threat.txt's text: yes or no (also positive/negative, threat, 1/0).
bool parse_threat_text(std::string_view text, const std::string& source);

}  // namespace portalsim
