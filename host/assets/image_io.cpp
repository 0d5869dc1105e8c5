#include "assets/image_io.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <mutex>

#include "assets/png_writer.h"
#include "base/error.h"
#include "io/input_file.h"

namespace portalsim {

namespace {
OIIO::ImageSpec spec_of(const Image& img) {
  return OIIO::ImageSpec(img.width, img.height, img.channels, OIIO::TypeDesc::UINT8);
}
}  // namespace

namespace {
// libpng prints its complaints to stderr and OpenImageIO's PNG reader echoes them to
// stdout; OpenImageIO's error string carries the same text, and that is what portalsim
// reports. Both streams are held shut while decoding.
class QuietOutput {
 public:
  QuietOutput() : lock_(mutex()) {
    std::fflush(stdout);
    std::fflush(stderr);
    const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    for (int i = 0; i < 2; ++i) {
      saved_[i] = ::dup(kFds[i]);
      if (saved_[i] >= 0 && null >= 0) ::dup2(null, kFds[i]);
    }
    if (null >= 0) ::close(null);
  }
  ~QuietOutput() {
    std::fflush(stdout);
    std::fflush(stderr);
    for (int i = 0; i < 2; ++i)
      if (saved_[i] >= 0) {
        ::dup2(saved_[i], kFds[i]);
        ::close(saved_[i]);
      }
  }

 private:
  static constexpr int kFds[2] = {STDOUT_FILENO, STDERR_FILENO};
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  std::lock_guard<std::mutex> lock_;
  int saved_[2] = {-1, -1};
};
}  // namespace

Image read_image(const std::string& path, const std::string& origin) {
  const std::string where = origin + ": " + path;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(where + ": no such image file");
  try {
    io::check_regular_file(path, "image", io::kMaxImageBytes);
  } catch (const InputError& e) {
    throw InputError(origin + ": " + e.what());
  }
  std::string error;
  Image img;
  {
    QuietOutput quiet;
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
      if (spec.width < 1 || spec.height < 1 || spec.width > kMaxImageSide || spec.height > kMaxImageSide ||
          static_cast<int64_t>(spec.width) * spec.height > kMaxImagePixels || spec.depth != 1) {
        error = "image is " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " pixels; at most " +
                std::to_string(kMaxImageSide) + " a side and " + std::to_string(kMaxImagePixels) + " pixels in all";
      } else if (spec.nchannels < 1 || spec.nchannels > 4) {
        error =
            "image has " + std::to_string(spec.nchannels) + " channels; expected 1 to 4 (gray, gray+alpha, RGB, RGBA)";
      } else if (depth != OIIO::TypeDesc::UINT8 && depth != OIIO::TypeDesc::UINT16) {
        error = std::string("image samples are ") + spec.format.c_str() + "; expected 8- or 16-bit integers";
      } else {
        img = Image(spec.width, spec.height, spec.nchannels);
        const bool ok = in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, img.pixels.data());
        const std::string err = in->geterror();
        if (!ok || !err.empty()) error = "corrupt or unreadable image" + (err.empty() ? "" : ": " + err);
      }
      in->close();
      in->geterror();
    }
    OIIO::geterror();  // nothing left pending to be printed later
  }
  if (!error.empty()) {
    // OpenImageIO's messages may span lines; one error, one line.
    while (!error.empty() && (error.back() == '\n' || error.back() == ' ')) error.pop_back();
    for (size_t p; (p = error.find('\n')) != std::string::npos;) error.replace(p, 1, "; ");
    throw InputError(where + ": " + error);
  }
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

void write_image(const std::string& path, const Image& img, int png_level, int jpeg_quality) {
  // PNG through portalsim's own writer (png_writer.h: several times faster for the many
  // small files of image folders); every other format through OpenImageIO.
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".png" || ext == ".PNG") {
    write_png(path, img.pixels.data(), img.width, img.height, img.channels, png_level);
    return;
  }
  // Failures here are the disk's or the folder's (full, read-only): output errors.
  auto out = OIIO::ImageOutput::create(path);
  if (!out) throw OutputError(path + ": cannot write image: " + OIIO::geterror());
  OIIO::ImageSpec spec = spec_of(img);
  spec.attribute("CompressionQuality", jpeg_quality);
  if (!out->open(path, spec)) throw OutputError(path + ": cannot write image: " + out->geterror());
  const bool ok = out->write_image(OIIO::TypeDesc::UINT8, img.pixels.data());
  const bool closed = out->close();
  if (!ok || !closed) throw OutputError(path + ": cannot write image: " + out->geterror());
}

}  // namespace portalsim
