// portalsim's OpenImageIO module (codec.h): the only code that links OpenImageIO.
#include "assets/oiio/codec.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <cstdint>

namespace portalsim::oiio {
namespace {

OIIO::ImageSpec spec_of(const Image& img) {
  return OIIO::ImageSpec(img.width, img.height, img.channels, OIIO::TypeDesc::UINT8);
}

std::string read(const std::string& path, const ImageLimits& limits, Image& img) {
  std::string error;
  // create() then open(), not ImageInput::open(): a failed open() inside the latter
  // leaves an uncollected error that OpenImageIO prints at exit.
  auto in = OIIO::ImageInput::create(path);
  OIIO::ImageSpec opened;
  if (!in) {
    error = "cannot read image: " + OIIO::geterror();
  } else if (!in->open(path, opened)) {
    error = "cannot read image: " + in->geterror();
  } else {
    const OIIO::ImageSpec& spec = in->spec();
    // Checked from the header, before decoding: a small file must not decode to gigabytes.
    const OIIO::TypeDesc::BASETYPE depth = static_cast<OIIO::TypeDesc::BASETYPE>(spec.format.basetype);
    if (spec.width < 1 || spec.height < 1 || spec.width > limits.max_side || spec.height > limits.max_side ||
        static_cast<int64_t>(spec.width) * spec.height > limits.max_pixels || spec.depth != 1) {
      error = "image is " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " pixels; at most " +
              std::to_string(limits.max_side) + " a side and " + std::to_string(limits.max_pixels) + " pixels in all";
    } else if (spec.nchannels < 1 || spec.nchannels > 4) {
      error =
          "image has " + std::to_string(spec.nchannels) + " channels; expected 1 to 4 (gray, gray+alpha, RGB, RGBA)";
    } else if (depth != OIIO::TypeDesc::UINT8 && depth != OIIO::TypeDesc::UINT16) {
      error = std::string("image samples are ") + spec.format.c_str() + "; expected 8- or 16-bit integers";
    } else {
      img = Image(spec.width, spec.height, spec.nchannels);
      // Asked for a conversion (even to the file's own type), OpenImageIO 2.4's read_image
      // reads scanline files through a 64 MiB buffer allocated per image: an 8-bit file is
      // read as it is (TypeDesc::UNKNOWN), a 16-bit one a row at a time, each converted to
      // 8 bits; a tiled 16-bit file (no rows to read) through read_image, tile by tile.
      bool ok = true;
      if (depth == OIIO::TypeDesc::UINT8) {
        ok = in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UNKNOWN, img.pixels.data());
      } else if (spec.tile_width != 0) {
        ok = in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, img.pixels.data());
      } else {
        const size_t row = static_cast<size_t>(spec.width) * spec.nchannels;
        for (int y = 0; ok && y < spec.height; ++y)
          ok = in->read_scanline(spec.y + y, 0, OIIO::TypeDesc::UINT8, img.pixels.data() + y * row);
      }
      const std::string err = in->geterror();
      if (!ok || !err.empty()) error = "corrupt or unreadable image" + (err.empty() ? "" : ": " + err);
    }
    in->close();
    in->geterror();
  }
  OIIO::geterror();  // nothing left pending to be printed later
  return error;
}

std::string resize(const Image& img, int width, int height, Image& out) {
  OIIO::ImageBuf src(spec_of(img), const_cast<uint8_t*>(img.pixels.data()));
  OIIO::ImageSpec dst_spec(width, height, img.channels, OIIO::TypeDesc::UINT8);
  OIIO::ImageBuf dst(dst_spec);
  if (!OIIO::ImageBufAlgo::resize(dst, src)) return "resize failed: " + dst.geterror();
  out = Image(width, height, img.channels);
  dst.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::UINT8, out.pixels.data());
  return "";
}

std::string write(const std::string& path, const Image& img, int jpeg_quality) {
  auto out = OIIO::ImageOutput::create(path);
  if (!out) return "cannot write image: " + OIIO::geterror();
  OIIO::ImageSpec spec = spec_of(img);
  spec.attribute("CompressionQuality", jpeg_quality);
  if (!out->open(path, spec)) return "cannot write image: " + out->geterror();
  const bool ok = out->write_image(OIIO::TypeDesc::UINT8, img.pixels.data());
  const bool closed = out->close();
  if (!ok || !closed) return "cannot write image: " + out->geterror();
  return "";
}

const Codec kCodec{kCodecVersion, read, resize, write};

}  // namespace
}  // namespace portalsim::oiio

extern "C" __attribute__((visibility("default"))) const portalsim::oiio::Codec* portalsim_oiio_codec() {
  return &portalsim::oiio::kCodec;
}
