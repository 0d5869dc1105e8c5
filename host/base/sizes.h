// Byte sizes that several layers agree on, named once.
#pragma once
#include <cstddef>

namespace portalsim {

inline constexpr size_t kMiB = size_t{1} << 20;

// What one piece of a copy or a read takes at once (merge's join, data.h5's rebuild from
// .npy, a scenario list read as a stream), and what one batch's outputs aim at: large
// enough that per-call costs vanish, small enough that a few fit in any cache budget.
inline constexpr size_t kIoPieceBytes = 16 * kMiB;

}  // namespace portalsim
