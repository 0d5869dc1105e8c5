/* The contract between the kernels (OpenCL C) and the host (C++), the CPU reference
 * included: counts, random stream ids, flags and record layouts. Constants and layouts
 * only: no function-like macro and no function (tests/layering_check.py enforces both), so
 * that each side implements every computation itself (docs/model/determinism.md) and a
 * wrong kernel cannot pass parity by sharing its mistake with the reference. The kernel
 * program is this file, kernels/shared.h, then the kernels/ sources. */
#ifndef PORTALSIM_CONTRACT_H
#define PORTALSIM_CONTRACT_H

/* The most regions of the body (thesis 4.1) and zones of the metal detector a catalogue
 * may declare: a view's region_mask has a bit per region, and a scenario's zones are bytes
 * on a row. The kernels are built with the catalogue's own counts, -DPS_REGIONS=N and
 * -DPS_ZONES=M (backend/opencl/kernels.cpp): the strides of the object and zone rows and
 * the bounds of the loops over them. */
#define PS_MAX_REGIONS 32
#define PS_MAX_ZONES 64
#ifdef __OPENCL_VERSION__
#if !defined(PS_REGIONS) || !defined(PS_ZONES)
#error "the kernels are built with the catalogue's counts, -DPS_REGIONS=N -DPS_ZONES=M"
#endif
/* Most sprites one camera view draws: one per region. */
#define PS_MAX_LAYERS PS_REGIONS
#endif

/* The metal detector under --model physics (docs/model/metal.md). */
/* Record of one zone's coils, doubles: transmit and receive coil position (x, z, metres;
 * y = 0) and moment (along x, A m^2), then the zone's gain. */
#define PS_MZ_TX_X 0
#define PS_MZ_TX_Z 1
#define PS_MZ_TX_M 2
#define PS_MZ_RX_X 3
#define PS_MZ_RX_Z 4
#define PS_MZ_RX_M 5
#define PS_MZ_GAIN 6
#define PS_MZ_LEN 8
/* Record of one region, doubles: its rectangle's centre in the portal's field (column, row
 * from the top; scene/sensor.h, Frame) as the view that places it draws it, then that view's
 * field units per pixel (across, negative for a back view; down) and its pixels per field
 * unit (the jitter's scale, across and down). */
#define PS_MR_COL 0
#define PS_MR_ROW 1
#define PS_MR_FIELD_PER_COL 2
#define PS_MR_FIELD_PER_ROW 3
#define PS_MR_JITTER_X 4
#define PS_MR_JITTER_Y 5
#define PS_MR_LEN 6
/* Each object is PS_METAL_SEGMENTS equal dipoles at the midpoints of equal segments of its
 * drawn long side (docs/model/metal.md). Record of one variant (or one oriented test object
 * of a metal map), doubles: its polarizability tensor (row-major 3x3, cm^3), then its long
 * side's x, z and y (metres; y is 0 for a catalogue variant). */
#define PS_METAL_SEGMENTS 5
#define PS_MV_LONG_X 9
#define PS_MV_LONG_Z 10
#define PS_MV_LONG_Y 11
#define PS_MV_LEN 12
/* A metal map's probe (host/evaluate/metal_map.h), doubles: the object's centre x, y, z
 * (metres) and the index of its record (PS_MV_*) as a double. */
#define PS_MP_X 0
#define PS_MP_Y 1
#define PS_MP_Z 2
#define PS_MP_OBJECT 3
#define PS_MP_LEN 4

/* Random streams of the counter generator: each kind of draw has its own, so adding one
 * never shifts another. element = the index within the stream named beside it. */
#define PS_STREAM_NOISE_PATTERN 1u     /* which MMW noise pattern a scenario gets; element 0 */
#define PS_STREAM_METAL_NOISE 2u       /* metal detector noise; element = zone */
#define PS_STREAM_PIXEL_NOISE 3u       /* per-pixel sensor noise; element = view << 28 | pixel / 2 */
#define PS_STREAM_BLOCK_NOISE 4u       /* block-mean noise model; element = feature */
#define PS_STREAM_JITTER 5u            /* sprite placement jitter; element = region */
#define PS_STREAM_RAW_NOISE 6u         /* physics: MMW noise per raw pixel; element: PS_GAUSS_ELEMENT */
#define PS_STREAM_IR_NOISE 7u          /* physics: IR noise per pixel; element: PS_GAUSS_ELEMENT */
#define PS_STREAM_TRANSFORM 8u         /* randomised objects: rotation, scale, flip; element = region */
#define PS_STREAM_FEATURE_NOISE 9u     /* physics features-only: NETD noise in feature space; PS_GAUSS_ELEMENT */
#define PS_STREAM_PIXEL_NOISE_FAST 10u /* per-pixel sensor noise, Irwin-Hall draws; PS_GAUSS_ELEMENT */
#define PS_STREAM_METAL_MAP 11u        /* metal maps' detector noise (host only); element = zone */
#define PS_STREAM_KNOB_DRAW 12u        /* knobs drawn per scenario (A..B); element = PS_DRAWN_* */
#define PS_STREAM_BODIES 13u           /* random bodies (host only); index = body, element = draw */
#define PS_STREAM_GENERATE 16u         /* scenario generators (host only) */
/* The knobs a run may draw per scenario, each its element of PS_STREAM_KNOB_DRAW, declared
 * with its knob (host/plan/knobs.cpp: drawable): the declarations give each its key, column,
 * draw and record, and its range to the kernels (PsDrawn). */
#define PS_DRAWN_METAL_NOISE 0u
#define PS_DRAWN_IR_NETD 1u
#define PS_DRAWN_PIXEL_NOISE 2u
#define PS_DRAWN_NETD 3u
#define PS_DRAWN_FRAMES 4u
#define PS_DRAWN_ILLUMINATION 5u
#define PS_DRAWN_WORN_MINUTES 6u
/* The outfit of a run whose clothing is drawn (--clothing): its class from word 0, its
 * outfit in the class from word 1 (PsPhys clothing). Not a numeric knob. */
#define PS_DRAWN_CLOTHING 7u
/* physics: the MMW display window's ends (--window L1..L2/H1..H2), each drawn from its range. */
#define PS_DRAWN_WINDOW_LO 8u
#define PS_DRAWN_WINDOW_HI 9u
/* physics: the MMW raw grid of a run given a list of grids (--mmw-raw 24x24,28x28): the
 * grid below(word 0, grids) of the list. The host draws it and runs each grid's scenarios
 * together (an index table, kernels/lib/philox.cl's scenario_index); not a numeric knob. */
#define PS_DRAWN_MMW_RAW 10u
/* physics: the share of the outer garment's folds and seams that lies doubled (--clothing-folds,
 * docs/model/clothing.md), under a drawn outfit. */
#define PS_DRAWN_CLOTHING_FOLDS 11u
#define PS_DRAWN_KNOBS 12 /* elements 0 .. PS_DRAWN_KNOBS - 1 */
/* physics: frame k >= 1 of the MMW camera's integration draws its NETD from stream
 * PS_STREAM_FRAME_NOISE + k (frame 0 from PS_STREAM_RAW_NOISE); element: PS_GAUSS_ELEMENT */
#define PS_STREAM_FRAME_NOISE 32u
/* physics: the MMW camera's automatic window spans these order statistics of the raw grid,
 * in thousandths (the 1st and 99th percentiles), rank round(q (cells - 1) / 1000) of the
 * sorted cells, and at least PS_WINDOW_MIN_SPAN kelvin. */
#define PS_WINDOW_LOW_PERMILLE 10
#define PS_WINDOW_HIGH_PERMILLE 990
#define PS_WINDOW_MIN_SPAN 1.0
/* PsViewLaunch.window_auto: the fixed window, the automatic one, or its ends drawn per scenario. */
#define PS_WINDOW_FIXED 0
#define PS_WINDOW_AUTO 1
#define PS_WINDOW_DRAWN 2
#define PS_PIXEL_NOISE_VIEW_SHIFT 28 /* element bit where a view's index starts */
/* The physics model's table Gaussians (docs/model/determinism.md): a cell's Gaussian is
 * the top PS_GAUSS_BITS bits of a 16-bit half of a draw's word, k, taken to
 * Phi^-1((k + 1/2) / PS_GAUSS_TABLE). 12 bits keep the kernels' table (16 KB of floats) in
 * the L1 cache, where 16 bits (256 KB) made every gather miss it; sd 1 - 1.6e-4. */
#define PS_GAUSS_BITS 12
#define PS_GAUSS_TABLE (1 << PS_GAUSS_BITS)
/* The Irwin-Hall draw (docs/model/determinism.md): the thesis model's pixel noise under
 * noise_draw irwin-hall, and the physics fast tier's NETD and IR draws (PS_FLAG_FAST_DRAWS).
 * A cell's 16-bit half (the table Gaussians' layout), its two bytes summed, s in 0..510,
 * t = (s - 255) / 255, g = t (C1 + t^2 (C3 + t^2 C5)): an odd quintic fitted to the normal's
 * quantiles (sd 1, excess kurtosis -0.010, KS distance 0.0033, |g| <= 3.365), no table. */
#define PS_IH_C1 2.3740347
#define PS_IH_C3 (-0.85662049)
#define PS_IH_C5 1.8473553
/* Per-launch flags of the render kernels. */
#define PS_FLAG_PATTERN_NOISE 1
#define PS_FLAG_PIXEL_NOISE 2
#define PS_FLAG_BILINEAR 4
#define PS_FLAG_AFFINE 8      /* randomised objects: sprites sampled through their inverse affine map */
#define PS_FLAG_FLIP 16       /* with PS_FLAG_AFFINE: mirror each object with probability 1/2 */
#define PS_FLAG_TABULATED 32  /* physics features-only: scenarios the object tables cover skip physics_raw */
#define PS_FLAG_FAST_DRAWS 64 /* physics: NETD and IR noise as Irwin-Hall draws (PS_IH_*), not the table */

/* Footprint record of the sparse features path, per (variant, region, subject), ints. */
#define PS_FP_SPRITE_X0 0
#define PS_FP_SPRITE_Y0 1
#define PS_FP_SPRITE_W 2
#define PS_FP_SPRITE_H 3
#define PS_FP_SPRITE_OFFSET 4 /* atlas offset of the sprite */
#define PS_FP_TILE_X0 5
#define PS_FP_TILE_Y0 6
#define PS_FP_X0 7 /* footprint, clipped to the view, exclusive ends */
#define PS_FP_Y0 8
#define PS_FP_X1 9
#define PS_FP_Y1 10
#define PS_FP_BLOCK_X0 11
#define PS_FP_BLOCK_Y0 12
#define PS_FP_BLOCKS_W 13
#define PS_FP_BLOCKS_H 14
#define PS_FP_DELTAS 15        /* offset of its block delta table */
#define PS_FP_SPRITE_PADDED 16 /* atlas offset of the sprite's padded copy (PS_PAD) */
#define PS_FP_LEN 17

/* The launch's records: 4-byte fields only, so host and device lay them out alike. */
#ifdef __OPENCL_VERSION__
#define PS_U32 uint
#define PS_I32 int
#define PS_F32 float
#else
#include <stdint.h>
#define PS_U32 uint32_t
#define PS_I32 int32_t
#define PS_F32 float
#endif
/* Where the physics model's tables lie in a launch's `phys` (PsViewLaunch.tables), derived
 * with them (host: physics_tables) and set in the launch as one. */
typedef struct {
  PS_I32 stride; /* stage_mmw_display's row stride of dx */
  /* stage_mmw_display's weights of each raw column for each view column (raw_width rows of
   * stride, zero past width), the first and last raw column of each run of 16 view columns
   * (2 per run), the weights of each raw row for each view row (height rows of raw_height),
   * and each view row's first and last raw row. */
  PS_I32 dx, dxband, dy, dyband;
} PsDisplayTables;
typedef struct {
  PS_I32 psf_radius; /* taps either side of the centre */
  PS_I32 gauss;      /* the PS_GAUSS_TABLE values of Phi^-1((k + 1/2) / PS_GAUSS_TABLE) */
  /* The IR contact shadow off the body (IR views): per subject, the lowest base image index
   * that is body (warmer than halfway from the room to the skin), then per variant its
   * shadow against the room, -coupling (room - object), where the object is not on the body,
   * then per subject the factor of every shadow on it: (its skin - room) / (skin - room). */
  PS_I32 off_body;
  /* The MMW physics fast path's tables: the raw grid's weights of each view column
   * (raw_width x width) and row (raw_height x height), optics and sampling folded in; the
   * first and last raw column of each view column and raw row of each view row (2 per);
   * and each subject's bare raw grid (subjects x raw_height x raw_width). */
  PS_I32 wx, wy, cband, rband, base;
  PsDisplayTables display;
} PsPhysTables;

/* One camera view's launch of a render stage, passed by value to every stage kernel. */
typedef struct {
  PS_U32 n;           /* scenarios in the batch */
  PS_I32 view;        /* camera view: base image slot, pixel noise element */
  PS_I32 views;       /* camera views per subject (stride of the base table) */
  PS_I32 sprite_set;  /* the view's sprite set (camera, scale, mirror): row of the sprite table */
  PS_I32 variants;    /* stride of the sprite and place tables */
  PS_U32 region_mask; /* bit r: region r is drawn in this view */
  PS_I32 width, height;
  PS_U32 seed_lo, seed_hi, first_lo, first_hi;
  PS_I32 patterns;           /* noise patterns in the catalogue */
  PS_I32 tile_size;          /* noise tile side */
  PS_I32 flags;              /* PS_FLAG_* */
  PS_F32 jitter_x, jitter_y; /* in this view's pixels */
  /* The physics model: the raw grid, and where its parameters lie in `phys`. */
  PS_I32 raw_width, raw_height;
  PS_I32 subjects; /* subjects in the catalogue (the layout of phys) */
  PsPhysTables tables;
  /* The MMW camera's processing: frames averaged (each its own NETD draw) and the window
   * (PS_WINDOW_FIXED, _AUTO or _DRAWN). */
  PS_I32 frames, window_auto;
  /* Randomised objects (PS_FLAG_AFFINE): the ranges of the angle (degrees) and the scale,
   * as floats, and the same four as doubles (low word, high word) for fp64 builds. */
  PS_F32 rotate_lo, rotate_hi, scale_lo, scale_hi;
  PS_U32 ranges_fp64[8];
} PsViewLaunch;

/* The physics model's parameters for one launch (kernels' `phys`): the camera kind's
 * scalars (PsPhysMmw, PsPhysIr), then from PS_PHYS_SUBJECTS a (gain, offset) pair per
 * subject turning its base image's gray into kelvin, then each variant's value (MMW: its
 * apparent temperature under clothing; IR: its contact shadow), then the PSF's
 * 2 psf_radius + 1 normalised taps (kernels/shared.h: PS_PHYS_VARIANTS, PS_PHYS_TAPS), then
 * the tables PsViewLaunch.tables places. Every value is a PS_PARAM, the kernels' parameter
 * precision: the host fills doubles and converts each (backend/opencl/buffers.h, params), so
 * a scalar's index is its place in its struct on both sides (tests/contract_layout_test.cpp). */
#ifdef __OPENCL_VERSION__
#if defined(PRECISION_FP64)
#define PS_PARAM double
#else
#define PS_PARAM float
#endif
#else
#define PS_PARAM double
#endif
/* The range of each knob drawn per scenario, by its element (PS_DRAWN_*): lo its value (where
 * drawn, its range's low end), hi its range's upper end (its value where fixed); 0 for the
 * outfit's and the raw grid's elements. The host fills it from the knobs' declarations
 * (host/plan/knobs.h, drawn_ranges); the kernels draw from it (kernels/lib/philox.cl,
 * drawn_real and drawn_whole), so a new drawn knob needs no route of its own. */
typedef struct {
  PS_PARAM lo[PS_DRAWN_KNOBS], hi[PS_DRAWN_KNOBS];
} PsDrawn;
/* Both kinds' first scalars (kernels/lib/physics.cl reads them for either); the thesis model's
 * view kernels read its drawn ranges alone. */
typedef struct {
  PsDrawn drawn;
  PS_PARAM window_min; /* K shown as gray 0 (MMW, drawn window: the lower end of its range) */
  PS_PARAM window_max; /* K shown as gray 255 (likewise) */
  /* Where the illumination or the worn time is drawn per scenario, the offset of the scene
   * block (0: neither is): whether the illumination is drawn, then per subject the change of
   * its (gain, offset) over the illumination's range, per variant its value's change over that
   * range, its change per unit of exp(-worn / tau), 1 / tau and exp(-worn_lo / tau)
   * (PS_SCENE_*), then (MMW) each subject's bare raw grid's change over the illumination's
   * range (kernels/lib/physics.cl, scene_draw). The worn time's range is PsDrawn's. */
  PS_PARAM scene;
  /* Where the clothing is drawn per scenario (--clothing), the offset of the clothing block (0:
   * the catalogue's clothing): its classes C, each outfit's stride, the offset of the MMW gray
   * grids (0 for IR), the offset of the MMW fold grids (0 where the folds (--clothing-folds)
   * are off or for IR), then per class its first outfit, then per class its
   * outfits' count (PS_CLOTHING_*), then each outfit's entry (PS_OUTFIT_*): its factor of every
   * IR shadow, the offset in the entry of its scene moves, its folds' factor k and reference
   * temperature T (a fold of share m turns a value v into T + (1 + f k m)(v - T)), then each
   * subject's (gain, offset) and each variant's value as at PS_PHYS_SUBJECTS, and where the scene
   * block is, each subject's and variant's moves as at its PS_SCENE_SUBJECTS. The gray grids
   * (MMW): each subject's base image's gray through the raw grid's weights, so that its bare grid
   * is gain G + offset (each raw cell's weights sum to 1; kernels/physics_raw.cl). The fold grids
   * (MMW): each subject's fold share m times its gray, then each subject's m alone, through the
   * same weights. */
  PS_PARAM clothing;
} PsPhys;
typedef struct {
  PsPhys common;
  /* K rms per raw pixel over the frames (kernel_netd) where neither the NETD nor the frames
   * is drawn (else the NETD, drawn from its range); 1 where the frames' mean is one draw of
   * NETD / sqrt(frames) (Plan::frames_approximated). */
  PS_PARAM netd, frames_as_one;
} PsPhysMmw;
typedef struct {
  PsPhys common; /* its NETD: common.drawn's PS_DRAWN_IR_NETD */
} PsPhysIr;
/* A third kind joins this union; the tails begin past the largest kind's scalars. */
typedef union {
  PsPhysMmw mmw;
  PsPhysIr ir;
} PsPhysKinds;
#define PS_PHYS_SUBJECTS ((int)(sizeof(PsPhysKinds) / sizeof(PS_PARAM)))
#define PS_CLOTHING_CLASSES 0
#define PS_CLOTHING_STRIDE 1
#define PS_CLOTHING_GRIDS 2
#define PS_CLOTHING_FOLD_GRIDS 3
#define PS_CLOTHING_FIRST 4 /* kernels/shared.h: PS_CLOTHING_OUTFITS */
#define PS_OUTFIT_SHADOW 0
#define PS_OUTFIT_MOVES 1
#define PS_OUTFIT_FOLD_K 2
#define PS_OUTFIT_FOLD_T 3
#define PS_OUTFIT_HEAD 4
#define PS_SCENE_SUBJECTS 1 /* kernels/shared.h: PS_SCENE_VARIANTS, PS_SCENE_BARE */

/* A camera view's placement record per scenario, written by place_view and read by
 * every render stage: the objects it draws, in region order, and the noise pattern. */
#define PS_REC_COUNT 0   /* layers */
#define PS_REC_PATTERN 1 /* the scenario's noise pattern, -1 for none */
#define PS_REC_LAYERS 2
#define PS_LAYER_X0 0 /* whole-pixel top-left corner, jitter rounded */
#define PS_LAYER_Y0 1
#define PS_LAYER_FX 2 /* sub-pixel top-left corner (float bits) */
#define PS_LAYER_FY 3
#define PS_LAYER_W 4
#define PS_LAYER_H 5
#define PS_LAYER_OFFSET 6  /* atlas offset of the sprite */
#define PS_LAYER_PADDED 7  /* atlas offset of its padded copy */
#define PS_LAYER_TILE_X0 8 /* the noise tile, centred on the unmoved sprite */
#define PS_LAYER_TILE_Y0 9
#define PS_LAYER_VARIANT 10 /* the object drawing */
/* Affine placement (PS_FLAG_AFFINE): the image box the transformed sprite can touch
 * (inclusive), then the inverse map, a sprite point (sx, sy) per image pixel (x, y):
 * sx = SCX + A00 (x - CX) + A01 (y - CY), sy = SCY + A10 (x - CX) + A11 (y - CY), each
 * value at the kernels' sample precision (a double, or a float and a spare int). */
#define PS_LAYER_BX0 11
#define PS_LAYER_BY0 12
#define PS_LAYER_BX1 13
#define PS_LAYER_BY1 14
#define PS_LAYER_CX 15 /* the sprite's centre in the image */
#define PS_LAYER_CY 17
#define PS_LAYER_A00 19
#define PS_LAYER_A01 21
#define PS_LAYER_A10 23
#define PS_LAYER_A11 25
#define PS_LAYER_LEN 27
#ifdef __OPENCL_VERSION__
#define PS_REC_LEN (PS_REC_LAYERS + PS_MAX_LAYERS * PS_LAYER_LEN)
#endif

/* The vector render path reads 16 pixels of a sprite or noise tile row at a time, so
 * each also lives padded: every row with PS_PAD neutral pixels on both sides (sprites:
 * coverage 0, as value row then coverage row; tiles: 128). */
#define PS_PAD 16

/* Work-group size of every launch: fixed, so PoCL compiles each kernel once. */
#define PS_LOCAL_SIZE 64

#endif
