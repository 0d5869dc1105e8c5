#include "assets/image_io.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <filesystem>

#include "scene/error.h"

namespace portalsim {

namespace {
OIIO::ImageSpec spec_of(const Image& img) {
  return OIIO::ImageSpec(img.width, img.height, img.channels, OIIO::TypeDesc::UINT8);
}
}  // namespace

Image read_image(const std::string& path, const std::string& origin) {
  const std::string where = origin + ": " + path;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(where + ": no such image file");
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw InputError(where + ": cannot read image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1 || spec.width > 16384 || spec.height > 16384 ||
      spec.nchannels > 16)
    throw InputError(where + ": unsupported image dimensions " + std::to_string(spec.width) + "x" +
                     std::to_string(spec.height) + "x" + std::to_string(spec.nchannels));
  Image img(spec.width, spec.height, spec.nchannels);
  const bool ok = in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, img.pixels.data());
  const std::string err = in->geterror();
  in->close();
  if (!ok || !err.empty())
    throw InputError(where + ": corrupt or unreadable image" + (err.empty() ? "" : ": " + err));
  return img;
}

Image resize_image(const Image& img, int width, int height) {
  if (img.width == width && img.height == height) return img;
  OIIO::ImageBuf src(spec_of(img), const_cast<uint8_t*>(img.pixels.data()));
  OIIO::ImageSpec dst_spec(width, height, img.channels, OIIO::TypeDesc::UINT8);
  OIIO::ImageBuf dst(dst_spec);
  if (!OIIO::ImageBufAlgo::resize(dst, src)) throw std::runtime_error("resize failed: " + dst.geterror());
  Image out(width, height, img.channels);
  dst.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::UINT8, out.pixels.data());
  return out;
}

void write_image(const std::string& path, const Image& img, int jpeg_quality) {
  auto out = OIIO::ImageOutput::create(path);
  if (!out) throw std::runtime_error(path + ": cannot write image: " + OIIO::geterror());
  OIIO::ImageSpec spec = spec_of(img);
  spec.attribute("CompressionQuality", jpeg_quality);
  spec.attribute("png:compressionLevel", 3);
  if (!out->open(path, spec)) throw std::runtime_error(path + ": cannot write image: " + out->geterror());
  const bool ok = out->write_image(OIIO::TypeDesc::UINT8, img.pixels.data());
  const bool closed = out->close();
  if (!ok || !closed) throw std::runtime_error(path + ": cannot write image: " + out->geterror());
}

}  // namespace portalsim
