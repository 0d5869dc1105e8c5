#include "assets/png_writer.h"

#include <isa-l/crc.h>
#include <isa-l/igzip_lib.h>

#include <cstring>
#include <stdexcept>
#include <vector>

#include "base/error.h"
#include "io/output_file.h"

namespace portalsim {

namespace {

void put32(std::string& out, uint32_t v) {
  const char b[4] = {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8),
                     static_cast<char>(v)};
  out.append(b, 4);
}

// Length, type, data, then the CRC-32 of type and data (PNG 1.2, section 5.3).
void chunk(std::string& out, const char* type, const uint8_t* data, size_t n) {
  put32(out, static_cast<uint32_t>(n));
  const size_t at = out.size();
  out.append(type, 4);
  if (n) out.append(reinterpret_cast<const char*>(data), n);
  put32(out, crc32_gzip_refl(0, reinterpret_cast<const unsigned char*>(out.data() + at), n + 4));
}

// Each thread keeps its rows and ISA-L's work buffer: no allocation per image.
struct Scratch {
  std::vector<uint8_t> rows, deflated, level_buf;
};
Scratch& scratch() {
  thread_local Scratch s;
  return s;
}

// A zlib stream (RFC 1950) of `raw` in stored deflate blocks: level 0.
void stored(const std::vector<uint8_t>& raw, std::vector<uint8_t>& z) {
  z.clear();
  z.push_back(0x78);
  z.push_back(0x01);  // deflate, 32 KiB window, no preset dictionary; 0x7801 % 31 == 0
  size_t at = 0;
  do {
    const size_t n = std::min<size_t>(65535, raw.size() - at);
    const bool last = at + n == raw.size();
    const uint8_t head[5] = {static_cast<uint8_t>(last), static_cast<uint8_t>(n), static_cast<uint8_t>(n >> 8),
                             static_cast<uint8_t>(~n), static_cast<uint8_t>(~n >> 8)};
    z.insert(z.end(), head, head + 5);
    z.insert(z.end(), raw.begin() + static_cast<std::ptrdiff_t>(at), raw.begin() + static_cast<std::ptrdiff_t>(at + n));
    at += n;
  } while (at < raw.size());
  const uint32_t a = isal_adler32(1, raw.data(), raw.size());
  for (int s = 24; s >= 0; s -= 8) z.push_back(static_cast<uint8_t>(a >> s));
}

void deflated(Scratch& s, int level) {
  const int isal_level = std::min(level - 1, ISAL_DEF_MAX_LEVEL);
  static constexpr uint32_t kLevelBuf[] = {ISAL_DEF_LVL0_DEFAULT, ISAL_DEF_LVL1_DEFAULT, ISAL_DEF_LVL2_DEFAULT,
                                           ISAL_DEF_LVL3_DEFAULT};
  s.level_buf.resize(kLevelBuf[isal_level]);
  // Room for stored blocks when nothing compresses, the zlib header and the checksum.
  s.deflated.resize(s.rows.size() + s.rows.size() / 16 + 1024);
  isal_zstream z;
  isal_deflate_stateless_init(&z);
  z.level = static_cast<uint32_t>(isal_level);
  z.level_buf = s.level_buf.empty() ? nullptr : s.level_buf.data();
  z.level_buf_size = static_cast<uint32_t>(s.level_buf.size());
  z.gzip_flag = IGZIP_ZLIB;
  z.end_of_stream = 1;
  z.flush = NO_FLUSH;
  z.next_in = s.rows.data();
  z.avail_in = static_cast<uint32_t>(s.rows.size());
  z.next_out = s.deflated.data();
  z.avail_out = static_cast<uint32_t>(s.deflated.size());
  const int r = isal_deflate_stateless(&z);
  if (r != COMP_OK) throw std::runtime_error("ISA-L deflate failed (" + std::to_string(r) + ")");
  s.deflated.resize(z.total_out);
}

}  // namespace

void encode_png(const uint8_t* pixels, int width, int height, int channels, int level, std::string& out) {
  if (channels < 1 || channels > 4) throw std::invalid_argument("encode_png: 1 to 4 channels");
  if (level < 0 || level > kMaxPngLevel) throw std::invalid_argument("encode_png: level out of range");
  Scratch& s = scratch();
  // Each row behind its filter byte, 0 (none): the data must be deflated whole anyway, and
  // a filter costs more time than it saves in size at the fast levels.
  const size_t row = static_cast<size_t>(width) * channels;
  s.rows.resize((row + 1) * static_cast<size_t>(height));
  for (int y = 0; y < height; ++y) {
    uint8_t* r = s.rows.data() + static_cast<size_t>(y) * (row + 1);
    r[0] = 0;
    std::memcpy(r + 1, pixels + static_cast<size_t>(y) * row, row);
  }
  if (level == 0)
    stored(s.rows, s.deflated);
  else
    deflated(s, level);

  static const uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  out.append(reinterpret_cast<const char*>(kSignature), 8);
  uint8_t ihdr[13] = {};
  for (int i = 0; i < 4; ++i) {
    ihdr[i] = static_cast<uint8_t>(static_cast<uint32_t>(width) >> (24 - 8 * i));
    ihdr[4 + i] = static_cast<uint8_t>(static_cast<uint32_t>(height) >> (24 - 8 * i));
  }
  ihdr[8] = 8;                                            // bits per sample
  static const uint8_t kColourType[5] = {0, 0, 4, 2, 6};  // gray, gray+alpha, RGB, RGBA
  ihdr[9] = kColourType[channels];                        // then compression, filter method, no interlace: 0
  chunk(out, "IHDR", ihdr, sizeof ihdr);
  chunk(out, "IDAT", s.deflated.data(), s.deflated.size());
  chunk(out, "IEND", nullptr, 0);
}

void write_png(const std::string& path, const uint8_t* pixels, int width, int height, int channels, int level) {
  thread_local std::string bytes;
  bytes.clear();
  encode_png(pixels, width, height, channels, level, bytes);
  io::write_file(path, bytes);
}

}  // namespace portalsim
