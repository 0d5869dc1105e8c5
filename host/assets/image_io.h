// Reading and writing image files: OpenImageIO, in a module loaded on first use
// (assets/oiio/codec.h), and png_writer.h for PNG output.
#pragma once
#include <string>

#include "assets/image.h"
#include "assets/png_writer.h"

namespace portalsim {

// Limits checked from an image's header before it is decoded.
inline constexpr int kMaxImageSide = 8192;
inline constexpr long long kMaxImagePixels = 4096LL * 4096;

// Reads any format OpenImageIO knows into 8 bits per channel, keeping its channels:
// a regular file of at most io::kMaxImageBytes, within the limits above, 1 to 4
// channels of 8- or 16-bit integers. Throws InputError("<origin>: <path>: <reason>") when missing, unreadable or
// corrupt.
Image read_image(const std::string& path, const std::string& origin);

// Resamples to width x height (OpenImageIO's filtered resize); returns the input when
// the size already matches.
Image resize_image(const Image& img, int width, int height);

// Writes by file extension (png, jpg, tif, ...): PNG through png_writer.h at
// `png_level` (0..9), the rest through OpenImageIO. Throws OutputError on failure.
void write_image(const std::string& path, const Image& img, int png_level = kDefaultPngLevel, int jpeg_quality = 95);

}  // namespace portalsim
