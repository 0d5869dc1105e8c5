// PNG files written in bulk: 8-bit gray, gray+alpha, RGB or RGBA, no row filter, the image data deflated by
// ISA-L (Debian libisal). Chosen over OpenImageIO's writer (libpng and zlib), libspng
// and libdeflate by measurement on portalsim's own images (docs/dev/speed-history.md,
// "PNG folders"): per scenario its fastest level takes a third of libdeflate's level-1
// CPU time and a sixth of OpenImageIO's, for files 28% larger than OpenImageIO's.
#pragma once
#include <cstdint>
#include <string>

#include "assets/image.h"

namespace portalsim {

// --png-level: 0 stores the pixels uncompressed; 1 (the default) is the fastest level that
// compresses; 2 and 3 are ISA-L's levels 1 and 2, smaller and slower; 4 to 9 are ISA-L's
// highest level, 3 (ISA-L has four).
inline constexpr int kDefaultPngLevel = 1;
inline constexpr int kMaxPngLevel = 9;

// The PNG file of `channels` (1 to 4) x width x height interleaved 8-bit samples, appended
// to `out`. The bytes depend only on the pixels and the level.
void encode_png(const uint8_t* pixels, int width, int height, int channels, int level, std::string& out);

// encode_png, then the file at `path` (created or truncated). Throws OutputError naming it.
void write_png(const std::string& path, const uint8_t* pixels, int width, int height, int channels, int level);

}  // namespace portalsim
