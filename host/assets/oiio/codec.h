// The table of functions that portalsim's OpenImageIO module (libportalsim_oiio.so, built
// from codec.cpp) exports. OpenImageIO brings about 250 shared libraries with it, whose
// loading cost every process a quarter of a second at start; the module is loaded
// (dlopen) only when an image file is read, resized or written in a format other than PNG
// (assets/image_io.cpp). Each function returns "" on success or the reason it failed.
#pragma once
#include <string>

#include "assets/image.h"

namespace portalsim::oiio {

// Raised whenever a field below changes, so that a module from another build is refused.
inline constexpr int kCodecVersion = 1;

struct ImageLimits {
  int max_side = 0;
  long long max_pixels = 0;
};

struct Codec {
  int version = kCodecVersion;
  // Decodes to 8 bits per channel, keeping 1 to 4 channels of 8- or 16-bit integers; the
  // header is checked against `limits` before anything is decoded.
  std::string (*read)(const std::string& path, const ImageLimits& limits, Image& out) = nullptr;
  // OpenImageIO's filtered resize.
  std::string (*resize)(const Image& in, int width, int height, Image& out) = nullptr;
  // By file extension; `jpeg_quality` is OpenImageIO's CompressionQuality.
  std::string (*write)(const std::string& path, const Image& img, int jpeg_quality) = nullptr;
};

}  // namespace portalsim::oiio

// The module's one exported symbol.
extern "C" const portalsim::oiio::Codec* portalsim_oiio_codec();
