// Every stage of a camera view's chain, one line each: its name, whether it makes the stored
// 8-bit pixels (the last stage of every chain), and its kernels in launch order with what
// their work-items cover (StageItems, backend/stages.h). The name is its reference
// function's, reference::NAME (backend/reference/), and its kernel's after "stage_".
// reference/stages.h declares the functions from this list and backend/stages.cpp registers
// them, so a new stage is its files and its line here.
#pragma once

// clang-format off
#define PORTALSIM_STAGES(X)                                                                   \
  /* The thesis model. */                                                                     \
  X(composite, false, {"stage_composite", view_rows})     /* base image, then sprites */      \
  X(pattern_noise, false, {"stage_pattern_noise", view_rows}) /* MMW noise tile per object */ \
  X(sensor_noise, false, {"stage_sensor_noise", view_rows}) /* per-pixel Gaussian noise */    \
  X(display, true, {"stage_display", view_rows})          /* round half up, clamp 0..255 */   \
  /* The physics model's MMW camera (docs/model/physics-mmw.md). */                           \
  X(radiometry, false, {"stage_radiometry", view_rows})   /* apparent temperature, K */       \
  X(optics, false, {"stage_optics_rows", view_rows}, {"stage_optics_columns", view_rows})     \
  X(sample, false, {"stage_sample", raw_rows})            /* onto the raw grid */             \
  X(netd, false, {"stage_netd", raw_rows})                /* frames of NETD per raw pixel */  \
  X(window, false, {"stage_window", scenarios})           /* automatic window */              \
  X(mmw_display, true, {"stage_mmw_display", scenarios})  /* to the view, smooth, to gray */  \
  /* The physics model's IR camera (docs/model/physics-ir.md); heat spreading is the PSF's */ \
  /* separable Gaussian kernels over the taps its launch passes. */                           \
  X(contact_shadow, false, {"stage_contact_shadow", view_rows}) /* dT under clothing, K */    \
  X(heat_spread, false, {"stage_optics_rows", view_rows}, {"stage_optics_columns", view_rows}) \
  X(ir_surface, false, {"stage_ir_surface", view_rows})   /* plus the bare body's surface */  \
  X(ir_netd, false, {"stage_ir_netd", scenarios})         /* Gaussian noise per pixel */      \
  X(ir_display, true, {"stage_ir_display", scenarios})    /* to temperature index, round */
// clang-format on
