// Every bound the kernels are held to against the fp64 CPU reference, with its reason: one
// table per model, tier and output. Tests hold the kernels to it (check_tolerance in
// backend/compare.h), `portalsim tradeoff` reports where each tier lands, and
// docs/dev/testing.md prints it (tolerance_table_markdown; tests/golden_test.cpp checks
// that the page and the table agree).
#pragma once

#include <array>
#include <cstdio>
#include <string>

#include "plan/plan.h"

namespace portalsim {

// What is compared. Features come two ways: pooled from rendered images (any images
// plan), or from a features-only run, which the fast tier serves by its own path (the
// thesis's sparse pooling with the block-mean noise model; the physics model's raw grid).
// features_only_bias: a features-only run's features column by column, each one's mean
// error over the scenarios (the table's mean over all values hides an offset on a few).
enum class Output { pixels, features, features_only, features_only_noisy, features_only_bias, metal, masks };

struct Bound {
  Model model;
  Tier tier;
  Output output;
  double max_abs;          // per value (pixels: gray levels or temperature index)
  double mean_abs;         // mean over all values
  double share_differing;  // pixels: the share that may differ at all (1 where not bounded)
  // features_only_noisy: max_abs and mean_abs are multiples of the noise's standard
  // deviation on each compared value, over the noise-free bound of features_only.
  bool in_noise_sd;
  const char* reason;
};

// A pixel whose exact value is an x.5 tie (at alpha 0.9 over 0 or 255 every opaque pixel
// is one: 0.1 * 255 = 25.5) rounds by the last bit of the arithmetic, so how many pixels
// differ by one level depends on the images; the pixel shares below are the worst measured
// over the default catalogue and tests/extremes_test.cpp's black and white images, with
// margin. A feature is a mean of pixels, so its bound is the pixels' plus float rounding.
inline constexpr std::array kTolerances{
    // The thesis model.
    Bound{.model = Model::thesis,
          .tier = Tier::exact,
          .output = Output::pixels,
          .max_abs = 1,
          .mean_abs = 1e-3,
          .share_differing = 1e-3,
          .in_noise_sd = false,
          .reason = "fp64 with the reference's formulas: only x.5 ties and libm's last bits round apart"},
    Bound{.model = Model::thesis,
          .tier = Tier::exact,
          .output = Output::features,
          .max_abs = 0.05,
          .mean_abs = 1e-3,
          .share_differing = 1,
          .in_noise_sd = false,
          .reason = "means of pixels within the pixel bound (few differ), plus float rounding"},
    Bound{.model = Model::thesis,
          .tier = Tier::exact,
          .output = Output::features_only,
          .max_abs = 0.05,
          .mean_abs = 1e-3,
          .share_differing = 1,
          .in_noise_sd = false,
          .reason = "sparse pooling gives the dense path's numbers to the bit"},
    Bound{.model = Model::thesis,
          .tier = Tier::standard,
          .output = Output::pixels,
          .max_abs = 1,
          .mean_abs = 0.05,
          .share_differing = 0.05,
          .in_noise_sd = false,
          .reason = "fp32: ties, also carried through overlapping blends"},
    Bound{.model = Model::thesis,
          .tier = Tier::standard,
          .output = Output::features,
          .max_abs = 1.0 + 1e-4,
          .mean_abs = 0.05,
          .share_differing = 1,
          .in_noise_sd = false,
          .reason = "a mean of pixels each within 1, plus its float rounding"},
    Bound{.model = Model::thesis,
          .tier = Tier::standard,
          .output = Output::features_only,
          .max_abs = 1.0 + 1e-4,
          .mean_abs = 0.05,
          .share_differing = 1,
          .in_noise_sd = false,
          .reason = "sparse pooling gives the dense path's numbers to the bit"},
    Bound{.model = Model::thesis,
          .tier = Tier::fast,
          .output = Output::pixels,
          .max_abs = 2,
          .mean_abs = 0.5,
          .share_differing = 0.5,
          .in_noise_sd = false,
          .reason = "8.8 fixed point: alpha and noise gain quantised to 1/256"},
    Bound{.model = Model::thesis,
          .tier = Tier::fast,
          .output = Output::features,
          .max_abs = 2,
          .mean_abs = 0.5,
          .share_differing = 1,
          .in_noise_sd = false,
          .reason = "means of pixels each within 2"},
    Bound{.model = Model::thesis,
          .tier = Tier::fast,
          .output = Output::features_only,
          .max_abs = 2,
          .mean_abs = 0.5,
          .share_differing = 1,
          .in_noise_sd = false,
          .reason = "without pixel noise: sparse pooling of the fast tier's pixels"},
    Bound{.model = Model::thesis,
          .tier = Tier::fast,
          .output = Output::features_only_noisy,
          .max_abs = 6,
          .mean_abs = 1,
          .share_differing = 1,
          .in_noise_sd = true,
          .reason = "block-mean noise model: each mean gets one draw of N(0, sigma^2 / c), not the reference's pixels; "
                    "the difference of two independent draws has sd sigma sqrt(2 / c): 6 sd per value, 1 sd on average "
                    "(E|N(0, s)| = 0.8 s); statistically, the draws are N(0, 1) (moments and KS); where pixels clip at "
                    "0 or 255 the model does not hold and only the statistical check applies"},
    Bound{.model = Model::thesis,
          .tier = Tier::exact,
          .output = Output::metal,
          .max_abs = 0,
          .mean_abs = 0,
          .share_differing = 0,
          .in_noise_sd = false,
          .reason = "integers: the same table arithmetic"},
    Bound{.model = Model::thesis,
          .tier = Tier::standard,
          .output = Output::metal,
          .max_abs = 0,
          .mean_abs = 0,
          .share_differing = 0,
          .in_noise_sd = false,
          .reason = "integers: the same table arithmetic"},
    Bound{.model = Model::thesis,
          .tier = Tier::fast,
          .output = Output::metal,
          .max_abs = 0,
          .mean_abs = 0,
          .share_differing = 0,
          .in_noise_sd = false,
          .reason = "integers: the same table arithmetic"},
    // The physics model: its MMW chain ends in one rounding of a bilinear window; its IR
    // and metal sensors keep the tier's bounds where those are wider.
    Bound{.model = Model::physics,
          .tier = Tier::exact,
          .output = Output::pixels,
          .max_abs = 1,
          .mean_abs = 0.005,
          .share_differing = 0.005,
          .in_noise_sd = false,
          .reason = "MMW: one rounding of the displayed value; IR: the thesis tier's ties"},
    Bound{.model = Model::physics,
          .tier = Tier::exact,
          .output = Output::features,
          .max_abs = 1.0 + 1e-4,
          .mean_abs = 0.005 + 1e-4,
          .share_differing = 1,
          .in_noise_sd = false,
          .reason = "means of MMW pixels within 1, 0.5% of them off"},
    Bound{.model = Model::physics,
          .tier = Tier::exact,
          .output = Output::features_only,
          .max_abs = 1.0 + 1e-4,
          .mean_abs = 0.005 + 1e-4,
          .share_differing = 1,
          .in_noise_sd = false,
          .reason = "the dense path's features"},
    Bound{.model = Model::physics,
          .tier = Tier::standard,
          .output = Output::pixels,
          .max_abs = 1,
          .mean_abs = 0.05,
          .share_differing = 0.05,
          .in_noise_sd = false,
          .reason = "MMW: one rounding after fp32 optics and sampling; IR: the thesis tier's ties"},
    Bound{.model = Model::physics,
          .tier = Tier::standard,
          .output = Output::features,
          .max_abs = 1.0 + 1e-4,
          .mean_abs = 0.005 + 1e-4,
          .share_differing = 1,
          .in_noise_sd = false,
          .reason = "means of MMW pixels within 1, 0.5% of them off"},
    Bound{.model = Model::physics,
          .tier = Tier::standard,
          .output = Output::features_only,
          .max_abs = 1.0 + 1e-4,
          .mean_abs = 0.005 + 1e-4,
          .share_differing = 1,
          .in_noise_sd = false,
          .reason = "the dense path's features"},
    Bound{
        .model = Model::physics,
        .tier = Tier::fast,
        .output = Output::pixels,
        .max_abs = 2,
        .mean_abs = 0.5,
        .share_differing = 0.5,
        .in_noise_sd = false,
        .reason =
            "MMW: the display's sum taken raw rows first (the same linear map, floats rounded in another order) and "
            "one "
            "rounding; noise: Irwin-Hall draws and the frames as one draw of NETD / sqrt(frames), which the reference "
            "draws alike (reference/draws.cpp), so only the arithmetic differs"},
    Bound{.model = Model::physics,
          .tier = Tier::fast,
          .output = Output::features,
          .max_abs = 1.0 + 1e-4,
          .mean_abs = 0.005 + 1e-4,
          .share_differing = 1,
          .in_noise_sd = false,
          .reason = "means of MMW pixels within 1, 0.5% of them off (features pool the MMW views only)"},
    Bound{.model = Model::physics,
          .tier = Tier::fast,
          .output = Output::features_only,
          .max_abs = 0.75,
          .mean_abs = 0.3,
          .share_differing = 1,
          .in_noise_sd = false,
          .reason =
              "raw-grid path: means taken before the display's rounding and clamping, so up to half a level from "
              "the reference's means of rounded pixels; at block 1 a feature is one pixel (mean error 1/4), and a "
              "flat body rounds all one way (measured: 0.46 per value, 0.064 mean on the coverage set; 0.24 mean "
              "at block 1, 0.22 on flat black and white bodies)"},
    Bound{.model = Model::physics,
          .tier = Tier::fast,
          .output = Output::features_only_bias,
          .max_abs = 0.25,
          .mean_abs = 0.05,
          .share_differing = 1,
          .in_noise_sd = false,
          .reason = "raw-grid path at NETD 0, each feature's mean error over the coverage set: a block whose pixels "
                    "mostly round one way keeps that error in every scenario (measured: 0.236 at worst, a block of the "
                    "lower view; 0.028 on average over the columns)"},
    Bound{.model = Model::physics,
          .tier = Tier::fast,
          .output = Output::features_only_noisy,
          .max_abs = 6,
          .mean_abs = 1,
          .share_differing = 1,
          .in_noise_sd = true,
          .reason =
              "NETD drawn per feature with the per-pixel covariance, not the reference's draws: sd from that "
              "covariance, times sqrt 2; statistically, (kernel - reference) less their noise-free difference, over "
              "that sd, is N(0, 1) (moments and KS)"},
    Bound{.model = Model::physics,
          .tier = Tier::exact,
          .output = Output::metal,
          .max_abs = 0,
          .mean_abs = 0,
          .share_differing = 0,
          .in_noise_sd = false,
          .reason = "integers: rounded fp64 dipole sums"},
    Bound{.model = Model::physics,
          .tier = Tier::standard,
          .output = Output::metal,
          .max_abs = 0,
          .mean_abs = 0,
          .share_differing = 0,
          .in_noise_sd = false,
          .reason = "integers: rounded fp64 dipole sums"},
    Bound{.model = Model::physics,
          .tier = Tier::fast,
          .output = Output::metal,
          .max_abs = 0,
          .mean_abs = 0,
          .share_differing = 0,
          .in_noise_sd = false,
          .reason = "integers: rounded fp64 dipole sums"},
    // Masks and boxes are not a kernel output: both backends place sprites with one host
    // function (backend/annotate.cpp), so they are equal by construction, whatever the tier.
    Bound{.model = Model::thesis,
          .tier = Tier::exact,
          .output = Output::masks,
          .max_abs = 0,
          .mean_abs = 0,
          .share_differing = 0,
          .in_noise_sd = false,
          .reason = "one host function for both backends"},
    Bound{.model = Model::thesis,
          .tier = Tier::standard,
          .output = Output::masks,
          .max_abs = 0,
          .mean_abs = 0,
          .share_differing = 0,
          .in_noise_sd = false,
          .reason = "one host function for both backends"},
    Bound{.model = Model::thesis,
          .tier = Tier::fast,
          .output = Output::masks,
          .max_abs = 0,
          .mean_abs = 0,
          .share_differing = 0,
          .in_noise_sd = false,
          .reason = "one host function for both backends"},
    Bound{.model = Model::physics,
          .tier = Tier::exact,
          .output = Output::masks,
          .max_abs = 0,
          .mean_abs = 0,
          .share_differing = 0,
          .in_noise_sd = false,
          .reason = "one host function for both backends"},
    Bound{.model = Model::physics,
          .tier = Tier::standard,
          .output = Output::masks,
          .max_abs = 0,
          .mean_abs = 0,
          .share_differing = 0,
          .in_noise_sd = false,
          .reason = "one host function for both backends"},
    Bound{.model = Model::physics,
          .tier = Tier::fast,
          .output = Output::masks,
          .max_abs = 0,
          .mean_abs = 0,
          .share_differing = 0,
          .in_noise_sd = false,
          .reason = "one host function for both backends"},
};

// The Irwin-Hall pixel draw (noise_draw irwin-hall; docs/model/determinism.md): the kernels
// compute it in float, the reference in double, from the same bits. |g| <= 3.37, where a
// float ulp is 2.4e-7, and t, t^2, two fma()s and a multiply each round once: 5 half-ulps of
// the largest value, 6e-7, with margin.
inline constexpr double kIrwinHallDrawAbs = 2e-6;
// The table Gaussian (the physics cameras' NETD): the kernels read a float table of the
// reference's double quantiles, |g| <= 3.67: half a float ulp there is 2.4e-7.
inline constexpr double kTableGaussianAbs = 5e-7;
// Its distribution, exact over the 511 byte sums (determinism.md, worked in double): the
// statistics that tests and `portalsim tradeoff` hold a sample of n draws to, each within 4
// of its sampling sds (sd of the mean 1/sqrt(n), of the sd 1/sqrt(2n), of the skewness
// sqrt(6/n), of the excess kurtosis sqrt(24/n)); the sample's KS distance from the normal
// within the exact one plus the 0.001 critical value (compare_samples).
struct DrawDistribution {
  double mean, sd, skewness, excess_kurtosis, ks_from_normal;
};
inline constexpr DrawDistribution kIrwinHallDistribution{0.0, 1.0, 0.0, -0.010137, 0.0032609};

// The block-mean noise model's draws (the thesis fast tier's features-only runs with pixel
// noise), recovered from a feature as (feature - noise-free feature) / (sigma / sqrt(c)):
// Box-Muller in float under -cl-fast-relaxed-math, where log, cos and sin may lose a few
// ulps each (|g| <= 5.8: 1e-5), and the feature's float rounding (1.5e-5 at 255) over
// sigma / sqrt(c) (at least 0.02 in the tests: 1e-3). A draw's error within
// kBlockMeanDrawAbs + kBlockMeanDrawRel |g|, plus that rounding, with margin.
inline constexpr double kBlockMeanDrawAbs = 1e-4, kBlockMeanDrawRel = 1e-4;

inline const char* output_name(Output o) {
  switch (o) {
    case Output::pixels:
      return "pixels";
    case Output::features:
      return "features (from images)";
    case Output::features_only:
      return "features-only run";
    case Output::features_only_noisy:
      return "features-only run, with noise";
    case Output::features_only_bias:
      return "features-only run, each feature's mean error";
    case Output::metal:
      return "metal zones";
    case Output::masks:
      return "masks and boxes";
  }
  return "?";
}

// The table's row; every (model, tier, output) has one but features_only_noisy under the
// exact and standard tiers, which draw the reference's noise (features_only's row).
inline const Bound& tolerance_bound(Model m, Tier t, Output o) {
  if (o == Output::features_only_noisy && t != Tier::fast) o = Output::features_only;
  for (const Bound& b : kTolerances)
    if (b.model == m && b.tier == t && b.output == o) return b;
  static const Bound none{m, t, o, 0, 0, 0, false, "no row: nothing may differ"};
  return none;
}

// The bounds check_tolerance applies to one run against the reference.
struct Tolerance {
  int pixel_max_abs;             // gray levels (MMW) and temperature index (IR)
  double pixel_mean_abs;         // over all pixels of a camera
  double pixel_share_differing;  // share of pixels that may differ at all
  double feature_max_abs;        // runs that render images
  double feature_mean_abs;
  double features_only_max_abs;  // features-only runs, without the block-mean noise model
  double features_only_mean_abs;
  // Metal zones and labels are integers and match exactly in every tier.
};

inline Tolerance model_tolerance(Model m, Tier t) {
  const Bound& px = tolerance_bound(m, t, Output::pixels);
  const Bound& f = tolerance_bound(m, t, Output::features);
  const Bound& fo = tolerance_bound(m, t, Output::features_only);
  return {
      static_cast<int>(px.max_abs), px.mean_abs, px.share_differing, f.max_abs, f.mean_abs, fo.max_abs, fo.mean_abs};
}
inline Tolerance tier_tolerance(Tier t) { return model_tolerance(Model::thesis, t); }

// The table as Markdown, for docs/dev/testing.md.
inline std::string tolerance_table_markdown() {
  std::string s =
      "| Model | Tier | Output | Per value | Mean | Pixels differing | Why |\n"
      "|---|---|---|---|---|---|---|\n";
  auto num = [](double v, bool sd) {
    char b[48];
    std::snprintf(b, sizeof b, "%g%s", v, sd ? " sd" : "");
    return std::string(b);
  };
  for (const Bound& b : kTolerances) {
    const bool exact = b.max_abs == 0 && b.mean_abs == 0;
    s += std::string("| ") + (b.model == Model::physics ? "physics" : "thesis") + " | " + tier_name(b.tier) + " | " +
         output_name(b.output) + " | " + (exact ? "exact" : num(b.max_abs, b.in_noise_sd)) + " | " +
         (exact ? "exact" : num(b.mean_abs, b.in_noise_sd)) + " | " +
         (b.output == Output::pixels ? num(b.share_differing, false) : "") + " | " + b.reason + " |\n";
  }
  return s;
}

}  // namespace portalsim
