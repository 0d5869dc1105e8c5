/* The kernel side's macros: computations over kernels/contract.h's layouts, shared by the
 * kernels (OpenCL C) and the OpenCL host code, never by the CPU reference, which
 * implements each itself (tests/layering_check.py). The kernel program is
 * kernels/contract.h, this file, then the kernels/ sources. */
#ifndef PORTALSIM_SHARED_H
#define PORTALSIM_SHARED_H

#ifndef __OPENCL_VERSION__
#include "contract.h" /* in the kernel program it comes first, by concatenation */
#endif

/* The automatic window's order statistic of `permille` among `cells` sorted cells
 * (kernels/contract.h, PS_WINDOW_LOW_PERMILLE): rank round(permille (cells - 1) / 1000). */
#define PS_WINDOW_RANK(permille, cells) (((permille) * ((cells)-1) + 500) / 1000)

/* The physics model's table Gaussians (kernels/contract.h): cell p of a view's field (raw grid or pixels, row by
 * row) reads element view << 28 | (16 (p / 128) + p % 16) of its stream, the 16-bit half
 * (p / 16) % 2 (low first) of word (p % 128) / 32, whose top PS_GAUSS_BITS bits are k
 * (PS_GAUSS_INDEX), and takes k to Phi^-1((k + 1/2) / PS_GAUSS_TABLE). So one draw of the
 * generator gives 8 cells, and 16 draws side by side give 128 in runs of 16
 * (kernels/lib/gauss.cl, gauss128). 12 bits keep the table (16 KB of floats) in the L1
 * cache, where 16 bits (256 KB) made every gather miss it; sd 1 - 1.6e-4, |g| <= 3.67. */
#define PS_GAUSS_ELEMENT(view, p) (((PS_U32)(view) << PS_PIXEL_NOISE_VIEW_SHIFT) | (PS_U32)(16 * ((p) >> 7) + ((p)&15)))
#define PS_GAUSS_WORD(p) (((p)&127) >> 5)
#define PS_GAUSS_SHIFT(p) ((((p) >> 4) & 1) * 16)
#define PS_GAUSS_INDEX(word, p) (((word) >> (PS_GAUSS_SHIFT(p) + 16 - PS_GAUSS_BITS)) & (PS_GAUSS_TABLE - 1))
/* stage_mmw_display's scratch per scenario, in values: each view row weighted along y (H x
 * RW), 32 values of room for whole-vector stores, then the raw grid in rows of 32; or (the
 * fast tier's display) each raw row interpolated along x, RH rows of W rounded up to 16. */
#define PS_MMW_ROWS_SCRATCH(H, RW, RH) ((size_t)(H) * (size_t)(RW) + 32 + 32 * (size_t)(RH))
#define PS_MMW_DISPLAY_SCRATCH(W, H, RW, RH)                                      \
  (PS_MMW_ROWS_SCRATCH(H, RW, RH) > (size_t)(RH) * (size_t)(((W) + 15) / 16 * 16) \
       ? PS_MMW_ROWS_SCRATCH(H, RW, RH)                                           \
       : (size_t)(RH) * (size_t)(((W) + 15) / 16 * 16))
/* physics_features' work space per scenario, in values: the features, band_x zeros, the
 * draws, band_y rows of zeros, Z Lx^T. Up to PS_FEATURE_NOISE_PRIVATE it lives in private
 * memory (the work-item's stack, in cache); larger layouts (small blocks) use global
 * scratch. */
#define PS_FEATURE_SPACE(bx, by, band_x, band_y, regions) (3 * (bx) * (by) + 2 * (regions) + (band_x) + (band_y) * (bx))
#define PS_FEATURE_NOISE_PRIVATE 2048

/* The metal detector under --model physics. */
#define PS_METAL_MAX_DEDUCTION 199          /* most one zone's response takes off its base value */
#define PS_METAL_FOUR_PI 12.566370614359172 /* 4 pi, the dipole field's denominator */
/* Offsets of the physics parameters' tails, past the kind's scalars (kernels/contract.h). */
#define PS_PHYS_VARIANTS(S) (PS_PHYS_SUBJECTS + 2 * (S))
#define PS_PHYS_TAPS(S, V) (PS_PHYS_VARIANTS(S) + (V))
/* The scene block's per-variant entries and bare grids' changes (PsPhys.scene). */
#define PS_SCENE_VARIANTS(S) (PS_SCENE_SUBJECTS + 2 * (S))
#define PS_SCENE_BARE(S, V) (PS_SCENE_VARIANTS(S) + 4 * (V))
/* The clothing block's first outfit entry, after C classes' first outfits and counts. */
#define PS_CLOTHING_OUTFITS(C) (PS_CLOTHING_FIRST + 2 * (C))

#endif
