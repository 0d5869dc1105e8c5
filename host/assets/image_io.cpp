#include "assets/image_io.h"

#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <mutex>
#include <vector>

#include "assets/oiio/codec.h"
#include "assets/png_writer.h"
#include "base/error.h"
#include "base/module.h"
#include "io/input_file.h"

namespace portalsim {

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

namespace {
const oiio::Codec& load_codec() {
  ModuleLoad load;
  if (const auto* codec =
          module_table<oiio::Codec>(PORTALSIM_OIIO_MODULE, "portalsim_oiio_codec", oiio::kCodecVersion, load))
    return *codec;
  throw EnvironmentError("image files are read and written by portalsim's OpenImageIO module " +
                         std::string(PORTALSIM_OIIO_MODULE) + ", " + (load.reason.empty() ? "not found" : load.reason) +
                         " (looked in: " + load.tried +
                         "); reinstall portalsim, or from a bundle unpack its images add-on, portalsim-" +
                         PORTALSIM_VERSION + "-linux-x86_64-images.tar.gz, over it");
}

// Loaded on first use, once for the process.
const oiio::Codec& codec() {
  static const oiio::Codec& c = load_codec();
  return c;
}
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
  const oiio::Codec& c = codec();
  {
    QuietOutput quiet;
    error = c.read(path, oiio::ImageLimits{kMaxImageSide, kMaxImagePixels}, img);
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
  Image out;
  const std::string error = codec().resize(img, width, height, out);
  if (!error.empty()) throw std::runtime_error(error);
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
  const std::string error = codec().write(path, img, jpeg_quality);
  if (!error.empty()) throw OutputError(path + ": " + error);
}

}  // namespace portalsim
