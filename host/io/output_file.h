// Writing a whole file in one call, without stream buffers: the many small files of
// image folders (PNGs, YOLO boxes, labels).
#pragma once
#include <string>
#include <string_view>

namespace portalsim::io {

// Creates or truncates `path` and writes `bytes`. On failure the partial file is removed and
// OutputError names the path and the reason (cannot open, disk full).
void write_file(const std::string& path, std::string_view bytes);

}  // namespace portalsim::io
