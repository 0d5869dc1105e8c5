// Helpers (kernels/lib/): the physics model's per-scenario draws (scene, clothing, folds),
// the bare body's kelvin, the objects' values, the MMW noise and frames, the display
// window, the tabulated-features test, and the IR camera's shadows, NETD and window: each
// used by a stage kernel and a fast path.

// The view's scalars (kernels/contract.h): either kind's first ones, the MMW camera's.
inline global const PsPhys* phys_common(global const param* phys) { return (global const PsPhys*)phys; }
inline global const PsPhysMmw* phys_mmw(global const param* phys) { return (global const PsPhysMmw*)phys; }

// The illumination, worn time and outfit of a scenario where drawn per scenario (PsPhys's scene
// and clothing; host: drawn_knob_at, outfit_at): at, the scene
// block's offset (0: neither drawn); t, the illumination's place in its range (uniform24 of
// PS_DRAWN_ILLUMINATION's word 0); w, the worn time in minutes; outfit, the outfit's index
// (-1: the catalogue's clothing); head, each subject's (gain, offset) then each variant's
// value under it; moves, each subject's then each variant's moves with the scene; shadow,
// its factor of every IR shadow; fold and fold_t, its folds' f k and T (0: no folds), so that
// a value v where the fold pattern's share is m turns into fold_t + (1 + fold m)(v - fold_t)
// (host: drawn_knob_at; PS_OUTFIT_FOLD_K).
typedef struct {
  int at, outfit;
  preal t, w, shadow, fold, fold_t;
  global const param* head;
  global const param* moves;
} SceneDraw;

inline SceneDraw scene_draw(global const param* phys, uint2 seed, ulong index) {
  SceneDraw d;
  d.at = (int)phys_common(phys)->scene;
  d.t = 0;
  d.w = 0;
  d.outfit = -1;
  d.shadow = 1;
  d.fold = 0;
  d.fold_t = 0;
  d.head = phys + PS_PHYS_SUBJECTS;
  d.moves = phys + d.at + PS_SCENE_SUBJECTS;
  const int clothing = (int)phys_common(phys)->clothing;
  if (clothing != 0) {
    global const param* c = phys + clothing;
    const uint classes = (uint)c[PS_CLOTHING_CLASSES];
    const uint2 w = draw(seed, index, PS_STREAM_KNOB_DRAW, PS_DRAWN_CLOTHING).xy;
    const uint k = below(w.x, classes);
    d.outfit = (int)c[PS_CLOTHING_FIRST + k] + (int)below(w.y, (uint)c[PS_CLOTHING_FIRST + classes + k]);
    global const param* e = c + PS_CLOTHING_OUTFITS(classes) + (size_t)d.outfit * (size_t)c[PS_CLOTHING_STRIDE];
    d.shadow = (preal)e[PS_OUTFIT_SHADOW];
    if (phys_drawn(phys)->hi[PS_DRAWN_CLOTHING_FOLDS] > 0) {
      const preal f = drawn_real(phys_drawn(phys), PS_DRAWN_CLOTHING_FOLDS, seed, index);
      d.fold = f * (preal)e[PS_OUTFIT_FOLD_K];
      d.fold_t = (preal)e[PS_OUTFIT_FOLD_T];
    }
    d.head = e + PS_OUTFIT_HEAD;
    d.moves = e + (int)e[PS_OUTFIT_MOVES];
  }
  if (d.at == 0) return d;
  global const param* b = phys + d.at;
  if (b[0] != 0) d.t = (preal)uniform24(draw(seed, index, PS_STREAM_KNOB_DRAW, PS_DRAWN_ILLUMINATION).x);
  d.w = drawn_real(phys_drawn(phys), PS_DRAWN_WORN_MINUTES, seed, index);
  return d;
}

// Subject s's (gain, offset) in the scenario: the view's (under its outfit), moved with the
// illumination.
inline void subject_kelvin(const SceneDraw* d, int s, preal* gain, preal* offset) {
  *gain = (preal)d->head[2 * s];
  *offset = (preal)d->head[2 * s + 1];
  if (d->at == 0) return;
  *gain += (preal)d->moves[2 * s] * d->t;
  *offset += (preal)d->moves[2 * s + 1] * d->t;
}

// A gray value's kelvin through a subject's (gain, offset) (subject_kelvin), for one value
// and for 16: the one text of the bare body's surface (radiometry, ir_surface and their
// fast paths).
#define GRAY_KELVIN(F) \
  inline F __attribute__((overloadable)) gray_kelvin(preal gain, F gray, preal offset) { return gain * gray + offset; }
GRAY_KELVIN(preal)
#if !defined(PRECISION_FP64)
GRAY_KELVIN(float16)
#endif

// Each variant's value in the scenario's outfit (PS_PHYS_VARIANTS where the clothing is the
// catalogue's).
inline global const param* variant_values(const SceneDraw* d, int subjects) { return d->head + 2 * subjects; }

// Each of a row's layers' value in the scenario: its variant's in `value`, moved where the
// illumination or the worn time is drawn.
inline void layer_values(const Layers* Ly, global const param* value, const SceneDraw* d, int subjects, preal* lv) {
  for (int k = 0; k < Ly->count; ++k) {
    lv[k] = (preal)value[Ly->variant[k]];
    if (d->at == 0) continue;
    global const param* v = d->moves + 2 * subjects + 4 * Ly->variant[k];
    lv[k] += (preal)v[0] * d->t + (preal)v[1] * (exp(-d->w * (preal)v[2]) - (preal)v[3]);
  }
}

// Lays a row's objects over v at column x, each by its coverage, with its layer's value
// (layer_values).
inline preal lay_values(const Layers* Ly, global const uchar* atlas, int x, const preal* lv, preal v) {
  for (int k = 0; k < Ly->count; ++k) {
    const int sx = x - Ly->x0[k];
    if (sx < 0 || sx >= Ly->width[k]) continue;
    preal c;
    if (Ly->bilinear) {
      greal pv, cov;
      bilinear_sample(Ly, k, atlas, x, &pv, &cov);
      c = (preal)cov;
    } else {
      c = (preal)atlas[Ly->offset[k] + 2 * sx + 1] * ((preal)1 / (preal)255);
    }
    v = c * lv[k] + ((preal)1 - c) * v;
  }
  return v;
}

// A value's factor where the fold pattern's share is m (0 .. 255): v - fold_t scales by it.
inline preal fold_gain(const SceneDraw* d, uchar m) {
  return (preal)1 + d->fold * ((preal)m * ((preal)1 / (preal)255));
}

// Pixels [0, n) of a row v through the scenario's folds (fold_row's row m); none where it has none.
inline void fold_values(const SceneDraw* d, global const uchar* restrict m, global preal* restrict v, int n) {
  if (d->fold == 0) return;
  for (int x = 0; x < n; ++x) v[x] = d->fold_t + fold_gain(d, m[x]) * (v[x] - d->fold_t);
}

// The optics stage's PSF taps, centred: taps[-R .. R] (stage_optics_*, heat_spread).
inline global const param* psf_taps(global const param* phys, const PsViewLaunch* L) {
  return phys + PS_PHYS_TAPS(L->subjects, L->variants) + L->tables.psf_radius;
}

// The stream of MMW frame k's noise (stage_netd, netd_frames).
inline uint frame_stream(int k) { return k == 0 ? PS_STREAM_RAW_NOISE : PS_STREAM_FRAME_NOISE + (uint)k; }

// Scenario index's MMW noise where the NETD or the frames are drawn per scenario (host:
// drawn_knob_at): NETD in [lo, hi] (PS_STREAM_KNOB_DRAW, PS_DRAWN_NETD, real), frames
// in [flo, fhi] (PS_DRAWN_FRAMES, whole); *frames frames of the returned sd each, or under
// the block-mean noise model (as_one) one of NETD / sqrt(frames).
inline preal mmw_noise_drawn(preal lo, preal hi, int flo, int fhi, bool as_one, uint2 seed, ulong index,
                             int* frames) {
  const preal netd = knob_draw(lo, hi, seed, index, PS_DRAWN_NETD);
  const int f = knob_draw(flo, fhi, seed, index, PS_DRAWN_FRAMES);
  *frames = as_one ? 1 : f;
  return as_one ? netd / sqrt((preal)f) : netd / (preal)f;
}

// Scenario index's MMW noise from the view's parameters: *frames frames (the launch's
// kframes where nothing is drawn) of the returned sd each.
inline preal mmw_noise_of(global const param* phys, int kframes, uint2 seed, ulong index, int* frames) {
  global const PsPhysMmw* p = phys_mmw(phys);
  global const PsDrawn* r = phys_drawn(phys);
  const preal hi = (preal)r->hi[PS_DRAWN_NETD];
  const int flo = (int)r->lo[PS_DRAWN_FRAMES], fhi = (int)r->hi[PS_DRAWN_FRAMES];
  if (hi <= (preal)r->lo[PS_DRAWN_NETD] && fhi <= flo) {
    *frames = kframes;
    return (preal)p->netd / (preal)kframes;
  }
  return mmw_noise_drawn((preal)p->netd, hi, flo, fhi, p->frames_as_one != 0, seed, index, frames);
}

// The netd stage over a scenario's whole raw grid v (physics_raw): L.frames frames of sd
// each added to every cell, frame after frame, as stage_netd's sums. fp32 builds hold a
// block of 128 cells in registers through all the frames and draw two frames' table
// Gaussians at once; the fast draws (one frame under the fast tier) go as noise_cells.
inline void netd_frames(global preal* restrict v, int cells, preal sd, int frames, uint2 seed, ulong index, int view,
                        global const param* table, bool fast) {
#if defined(PRECISION_FP64)
  for (int k = 0; k < frames; ++k) noise_cells(v, cells, sd, seed, index, frame_stream(k), view, table, fast);
#else
  if (fast) {
    for (int k = 0; k < frames; ++k) noise_cells(v, cells, sd, seed, index, frame_stream(k), view, table, true);
    return;
  }
  for (int p = 0; p < cells; p += 128) {
    const int n = min(cells - p, 128);
    float16 acc[8];
#pragma unroll
    for (int j = 0; j < 8; ++j) {
      if (16 * j + 16 <= n) {
        acc[j] = LOADF16(global, v + p + 16 * j);
      } else {
        float t[16];
        for (int q = 0; q < 16; ++q) t[q] = 16 * j + q < n ? v[p + 16 * j + q] : 0.0f;
        acc[j] = vload16(0, t);
      }
    }
    int k = 0;
    for (; k + 2 <= frames; k += 2) {
      float16 g[8], h[8];
      gauss128x2(seed, index, view, frame_stream(k), p >> 7, frame_stream(k + 1), p >> 7, table, g, h);
#pragma unroll
      for (int j = 0; j < 8; ++j) acc[j] = (acc[j] + sd * g[j]) + sd * h[j];
    }
    if (k < frames) {
      float16 g[8];
      gauss128(seed, index, frame_stream(k), view, p >> 7, table, g);
#pragma unroll
      for (int j = 0; j < 8; ++j) acc[j] = acc[j] + sd * g[j];
    }
#pragma unroll
    for (int j = 0; j < 8; ++j) {
      if (16 * j + 16 <= n) {
        STOREF16(global, acc[j], v + p + 16 * j);
      } else {
        float t[16];
        vstore16(acc[j], 0, t);
        for (int q = 0; 16 * j + q < n && q < 16; ++q) v[p + 16 * j + q] = t[q];
      }
    }
  }
#endif
}

// Scenario `index`'s drawn window ends (PS_WINDOW_DRAWN; host: drawn_knob_at), each uniform
// over its range (the lower ends are PsPhys's window_min and window_max).
inline void drawn_window(global const param* phys, uint2 seed, ulong index, preal* lo, preal* hi) {
  *lo = drawn_real(phys_drawn(phys), PS_DRAWN_WINDOW_LO, seed, index);
  *hi = drawn_real(phys_drawn(phys), PS_DRAWN_WINDOW_HI, seed, index);
}

// Kelvin t through a display window (lo, scale = 255 / (max - lo)) to a level 0..255,
// floor(x + 1/2) clamped: clamped before the truncation, which is then floor. One text for
// one value (window_level) and for 16 (window_level16; P is the scalar type, I the ints).
#define WINDOW_LEVEL(F, P, I, U, S)                                                   \
  inline U window_level##S(F t, P lo, P scale) {                                     \
    return convert_##U(convert_##I(fmin(fmax((t - lo) * scale + (P)0.5, (P)0), (P)255))); \
  }
#if defined(PRECISION_FP64)
WINDOW_LEVEL(double, double, int, uchar, )
#else
WINDOW_LEVEL(float, float, int, uchar, )
WINDOW_LEVEL(float16, float, int16, uchar16, 16)
#endif

// Whether two layers' boxes, widened by the bilinear fringe, meet.
inline bool layers_meet(global const int* a, global const int* b) {
  return a[PS_LAYER_X0] - 2 < b[PS_LAYER_X0] + b[PS_LAYER_W] + 2 && b[PS_LAYER_X0] - 2 < a[PS_LAYER_X0] + a[PS_LAYER_W] + 2 &&
         a[PS_LAYER_Y0] - 2 < b[PS_LAYER_Y0] + b[PS_LAYER_H] + 2 && b[PS_LAYER_Y0] - 2 < a[PS_LAYER_Y0] + a[PS_LAYER_H] + 2;
}

// Whether a scenario's view is its tabulated responses (features-only runs,
// PS_FLAG_TABULATED): each object's alone, plus a pair's correction where two boxes meet.
// That is exact when every object stands at its place (no jitter, no randomised
// transform) and meets at most one other (so no pixel lies under three).
inline bool physics_tabulated(global const int* rec, const PsViewLaunch* L) {
  if (!(L->flags & PS_FLAG_TABULATED) || (L->flags & PS_FLAG_AFFINE) || L->jitter_x > 0.0f || L->jitter_y > 0.0f)
    return false;
  for (int j = 0; j < rec[PS_REC_COUNT]; ++j) {
    int meets = 0;
    for (int k = 0; k < rec[PS_REC_COUNT]; ++k)
      meets += k != j && layers_meet(rec + PS_REC_LAYERS + j * PS_LAYER_LEN, rec + PS_REC_LAYERS + k * PS_LAYER_LEN);
    if (meets > 1) return false;
  }
  return true;
}

// A row's layers' shadows for subject s, against the skin (`on`) and the room (`off`): each
// variant's (layer_values) times the subject's skin above the room over the catalogue's
// skin's (the object warms towards its carrier's skin; host: the off-body block's last S),
// times the outfit's factor (its insulation over the catalogue clothing's).
inline void shadow_values(const Layers* Ly, const PsViewLaunch* L, global const param* phys, const SceneDraw* d, int s,
                          preal* on, preal* off) {
  global const param* off_body = phys + L->tables.off_body;
  layer_values(Ly, variant_values(d, L->subjects), d, L->subjects, on);
  layer_values(Ly, off_body + L->subjects, d, L->subjects, off);
  const preal skin = (preal)off_body[L->subjects + L->variants + s] * d->shadow;
  for (int k = 0; k < Ly->count; ++k) {
    on[k] *= skin;
    off[k] *= skin;
  }
}

// The scenario's IR NETD: the knob's, or where it is drawn per scenario its draw (host:
// drawn_knob_at).
inline preal ir_netd_of(global const param* phys, uint2 seed, ulong index) {
  return drawn_real(phys_drawn(phys), PS_DRAWN_IR_NETD, seed, index);
}

// The IR display window, kelvin to temperature index 0..255 (window_level), over pixels
// [a, b) of a view's T into o; fp32 builds 64 at a time (stage_ir_display, ir_surface_fused).
inline void ir_window(global const preal* restrict T, global uchar* restrict o, global const param* phys, int a,
                      int b) {
  const preal lo = (preal)phys_common(phys)->window_min;
  const preal scale = (preal)255 / ((preal)phys_common(phys)->window_max - lo);
  int p = a;
#if !defined(PRECISION_FP64)
  for (; p + 64 <= b; p += 64)
    store64(window_level16(vload16(0, T + p), lo, scale), window_level16(vload16(1, T + p), lo, scale),
            window_level16(vload16(2, T + p), lo, scale), window_level16(vload16(3, T + p), lo, scale), o + p);
  for (; p + 16 <= b; p += 16) store16(window_level16(vload16(0, T + p), lo, scale), o + p);
#endif
  for (; p < b; ++p) o[p] = window_level(T[p], lo, scale);
}
