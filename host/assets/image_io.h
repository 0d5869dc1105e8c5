// Reading and writing image files through OpenImageIO.
#pragma once
#include <string>

#include "assets/image.h"

namespace portalsim {

// Reads any format OpenImageIO knows into 8 bits per channel, keeping its channels.
// Throws InputError("<origin>: <path>: <reason>") when missing, unreadable or corrupt.
Image read_image(const std::string& path, const std::string& origin);

// Resamples to width x height (OpenImageIO's filtered resize); returns the input when
// the size already matches.
Image resize_image(const Image& img, int width, int height);

// Writes by file extension (png, jpg, tif, ...). Throws std::runtime_error on failure.
void write_image(const std::string& path, const Image& img, int jpeg_quality = 95);

}  // namespace portalsim
