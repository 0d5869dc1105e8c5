#include "assets/image_io.h"

#include <dlfcn.h>
#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <mutex>
#include <vector>

#include "assets/oiio/codec.h"
#include "assets/png_writer.h"
#include "base/error.h"
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
// The folders where the OpenImageIO module may be, in order: beside the object that holds
// this code (a build folder, the Python package), beside the executable, and where
// `cmake --install` puts it relative to bin/ (PORTALSIM_OIIO_MODULE_RELPATH).
std::vector<std::filesystem::path> module_folders() {
  namespace fs = std::filesystem;
  std::vector<fs::path> folders;
  Dl_info info{};
  std::error_code ec;
  if (dladdr(reinterpret_cast<void*>(&module_folders), &info) && info.dli_fname && *info.dli_fname)
    folders.push_back(fs::absolute(info.dli_fname, ec).parent_path());
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    folders.push_back(exe.parent_path());
    folders.push_back((exe.parent_path() / PORTALSIM_OIIO_MODULE_RELPATH).lexically_normal());
  }
  return folders;
}

const oiio::Codec& load_codec() {
  std::string tried, reason;
  for (const std::filesystem::path& folder : module_folders()) {
    const std::string file = (folder / PORTALSIM_OIIO_MODULE).string();
    tried += (tried.empty() ? "" : ", ") + file;
    if (!std::filesystem::exists(file)) continue;
    // Never closed: its functions serve the whole process.
    void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      reason = dlerror();
      continue;
    }
    using Entry = const oiio::Codec* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(handle, "portalsim_oiio_codec"));
    const oiio::Codec* codec = entry ? entry() : nullptr;
    if (codec && codec->version == oiio::kCodecVersion) return *codec;
    reason = file + " is from another build of portalsim";
  }
  throw EnvironmentError("image files are read and written by portalsim's OpenImageIO module " +
                         std::string(PORTALSIM_OIIO_MODULE) + ", " + (reason.empty() ? "not found" : reason) +
                         " (looked in: " + tried + "); reinstall portalsim");
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
