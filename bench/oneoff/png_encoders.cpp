// PNG writers compared on portalsim's own images: the measurement behind the choice of
// ISA-L for host/assets/png_writer.cpp (docs/dev/speed-history.md, "PNG folders").
// A one-off program, not part of the build (bench/oneoff/ is outside CMake's bench/*.cpp;
// it needs libspng-dev and libdeflate-dev, which portalsim does not):
//
//   g++ -O2 -std=c++20 bench/oneoff/png_encoders.cpp -o /tmp/png_encoders \
//       -lOpenImageIO -lOpenImageIO_Util -lspng -ldeflate -lisal
//   build/portalsim generate --count 100 --seed 1 --rule gun --what images --annotations --out /dev/shm/s
//   /tmp/png_encoders /dev/shm/s/images/*/{upper,lower,ir}.png    # then .../mask_*.png
//
// Each writer encodes every image five times; printed: the median CPU time of the calling
// thread per image (not wall time: the machine is shared), and the mean size. Every writer
// but OpenImageIO encodes to memory; "+ file" rows also write the file to /dev/shm.
#include <OpenImageIO/imageio.h>
#include <fcntl.h>
#include <isa-l/crc.h>
#include <isa-l/igzip_lib.h>
#include <libdeflate.h>
#include <spng.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

namespace {

struct Img {
  int w, h, c;
  std::vector<uint8_t> px;
};

Img load(const std::string& p) {
  auto in = OIIO::ImageInput::open(p);
  if (!in) std::exit(1);
  const OIIO::ImageSpec& s = in->spec();
  Img i{s.width, s.height, s.nchannels, std::vector<uint8_t>(size_t(s.width) * s.height * s.nchannels)};
  in->read_image(0, 0, 0, s.nchannels, OIIO::TypeDesc::UINT8, i.px.data());
  return i;
}

double cpu() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

const char* kFile = "/dev/shm/png_encoders.png";

void put(const std::vector<uint8_t>& b) {
  const int fd = ::open(kFile, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0 || ::write(fd, b.data(), b.size()) != ssize_t(b.size())) std::abort();
  ::close(fd);
}

// What portalsim wrote before: OpenImageIO (libpng, zlib), level 1, no row filter.
size_t oiio(const Img& img) {
  auto out = OIIO::ImageOutput::create(kFile);
  OIIO::ImageSpec spec(img.w, img.h, img.c, OIIO::TypeDesc::UINT8);
  spec.attribute("png:compressionLevel", 1);
  spec.attribute("png:filter", 8);
  out->open(kFile, spec);
  out->write_image(OIIO::TypeDesc::UINT8, img.px.data());
  out->close();
  return std::filesystem::file_size(kFile);
}

std::vector<uint8_t> spng(const Img& img, int level) {
  spng_ctx* ctx = spng_ctx_new(SPNG_CTX_ENCODER);
  spng_set_option(ctx, SPNG_ENCODE_TO_BUFFER, 1);
  spng_set_option(ctx, SPNG_IMG_COMPRESSION_LEVEL, level);
  spng_set_option(ctx, SPNG_FILTER_CHOICE, SPNG_FILTER_CHOICE_NONE);
  spng_ihdr ihdr{};
  ihdr.width = img.w;
  ihdr.height = img.h;
  ihdr.bit_depth = 8;
  ihdr.color_type = img.c == 1 ? SPNG_COLOR_TYPE_GRAYSCALE : SPNG_COLOR_TYPE_TRUECOLOR;
  spng_set_ihdr(ctx, &ihdr);
  if (spng_encode_image(ctx, img.px.data(), img.px.size(), SPNG_FMT_PNG, SPNG_ENCODE_FINALIZE)) std::abort();
  size_t n;
  int e;
  uint8_t* p = static_cast<uint8_t*>(spng_get_png_buffer(ctx, &n, &e));
  std::vector<uint8_t> v(p, p + n);
  std::free(p);
  spng_ctx_free(ctx);
  return v;
}

// The framing png_writer.cpp writes: signature, IHDR, one IDAT, IEND; rows unfiltered.
void be32(std::vector<uint8_t>& o, uint32_t x) {
  for (int s = 24; s >= 0; s -= 8) o.push_back(uint8_t(x >> s));
}
void chunk(std::vector<uint8_t>& o, const char* type, const uint8_t* d, size_t n) {
  be32(o, uint32_t(n));
  const size_t at = o.size();
  o.insert(o.end(), type, type + 4);
  o.insert(o.end(), d, d + n);
  be32(o, crc32_gzip_refl(0, o.data() + at, n + 4));
}
void rows_of(const Img& img, std::vector<uint8_t>& raw) {
  const size_t row = size_t(img.w) * img.c;
  raw.resize((row + 1) * img.h);
  for (int y = 0; y < img.h; ++y) {
    raw[y * (row + 1)] = 0;
    std::memcpy(&raw[y * (row + 1) + 1], &img.px[y * row], row);
  }
}
std::vector<uint8_t> framed(const Img& img, const uint8_t* z, size_t zn) {
  std::vector<uint8_t> o{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  uint8_t ih[13] = {};
  for (int i = 0; i < 4; ++i) {
    ih[i] = uint8_t(uint32_t(img.w) >> (24 - 8 * i));
    ih[4 + i] = uint8_t(uint32_t(img.h) >> (24 - 8 * i));
  }
  ih[8] = 8;
  ih[9] = img.c == 1 ? 0 : 2;
  chunk(o, "IHDR", ih, 13);
  chunk(o, "IDAT", z, zn);
  chunk(o, "IEND", nullptr, 0);
  return o;
}

std::vector<uint8_t> raw, z(1 << 21), level_buf(ISAL_DEF_LVL3_DEFAULT);

std::vector<uint8_t> libdeflate(libdeflate_compressor* c, const Img& img) {
  rows_of(img, raw);
  const size_t zn = libdeflate_zlib_compress(c, raw.data(), raw.size(), z.data(), z.size());
  return framed(img, z.data(), zn);
}

std::vector<uint8_t> isal(const Img& img, int level) {
  rows_of(img, raw);
  isal_zstream s;
  isal_deflate_stateless_init(&s);
  s.level = level;
  s.level_buf = level_buf.data();
  s.level_buf_size = uint32_t(level_buf.size());
  s.gzip_flag = IGZIP_ZLIB;
  s.end_of_stream = 1;
  s.next_in = raw.data();
  s.avail_in = uint32_t(raw.size());
  s.next_out = z.data();
  s.avail_out = uint32_t(z.size());
  if (isal_deflate_stateless(&s) != COMP_OK) std::abort();
  return framed(img, z.data(), s.total_out);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<Img> imgs;
  for (int i = 1; i < argc; ++i) imgs.push_back(load(argv[i]));
  if (imgs.empty()) return 2;
  size_t raw_bytes = 0;
  for (const Img& i : imgs) raw_bytes += i.px.size();
  const auto bench = [&](const char* name, auto fn) {
    std::vector<double> t;
    size_t bytes = 0;
    for (int rep = 0; rep < 5; ++rep) {
      const double a = cpu();
      bytes = 0;
      for (const Img& i : imgs) bytes += fn(i);
      t.push_back(cpu() - a);
    }
    std::sort(t.begin(), t.end());
    std::printf("| %s | %.1f | %.0f | %.1f%% |\n", name, 1e6 * t[2] / imgs.size(), double(bytes) / imgs.size(),
                100.0 * bytes / raw_bytes);
  };
  std::printf("%zu images, %.0f bytes each on average\n\n", imgs.size(), double(raw_bytes) / imgs.size());
  std::printf("| writer | CPU us per image | bytes per image | of raw |\n|---|---|---|---|\n");
  bench("OpenImageIO, zlib level 1, + file", oiio);
  bench("libspng 0.7.3, zlib level 1", [](const Img& i) { return spng(i, 1).size(); });
  for (int level : {1, 6}) {
    libdeflate_compressor* c = libdeflate_alloc_compressor(level);
    const std::string name = "libdeflate 1.14, level " + std::to_string(level);
    bench(name.c_str(), [&](const Img& i) { return libdeflate(c, i).size(); });
    libdeflate_free_compressor(c);
  }
  for (int level : {0, 1, 2, 3}) {
    const std::string name = "ISA-L 2.30, level " + std::to_string(level);
    bench(name.c_str(), [&](const Img& i) { return isal(i, level).size(); });
  }
  bench("ISA-L 2.30, level 0, + file", [](const Img& i) {
    const std::vector<uint8_t> v = isal(i, 0);
    put(v);
    return v.size();
  });
  std::remove(kFile);
}
