// Stage "radiometry" (physics model): the scene as apparent temperature, in kelvin. The
// subject's base image turns into kelvin through its subject's (gain, offset); each object,
// in region order, covers it by its sprite's coverage c: v = c T_object + (1 - c) v, where
// T_object is the variant's apparent temperature under clothing (host: PS_PHYS_VARIANTS).

// The illumination, worn time and outfit of a scenario where drawn per scenario (PS_PHYS_SCENE,
// PS_PHYS_CLOTHING; host: illumination_at, worn_minutes_at, outfit_at): at, the scene
// block's offset (0: neither drawn); t, the illumination's place in its range (uniform24 of
// PS_DRAWN_ILLUMINATION's word 0); w, the worn time in minutes; outfit, the outfit's index
// (-1: the catalogue's clothing); head, each subject's (gain, offset) then each variant's
// value under it; moves, each subject's then each variant's moves with the scene; shadow,
// its factor of every IR shadow; fold and fold_t, its folds' f k and T (0: no folds), so that
// a value v where the fold pattern's share is m turns into fold_t + (1 + fold m)(v - fold_t)
// (host: clothing_folds_at; PS_OUTFIT_FOLD_K).
typedef struct {
  int at, outfit;
  preal t, w, shadow, fold, fold_t;
  global const param* head;
  global const param* moves;
} SceneDraw;

inline SceneDraw scene_draw(global const param* phys, uint2 seed, ulong index) {
  SceneDraw d;
  d.at = (int)phys[PS_PHYS_SCENE];
  d.t = 0;
  d.w = 0;
  d.outfit = -1;
  d.shadow = 1;
  d.fold = 0;
  d.fold_t = 0;
  d.head = phys + PS_PHYS_SUBJECTS;
  d.moves = phys + d.at + PS_SCENE_SUBJECTS;
  const int clothing = (int)phys[PS_PHYS_CLOTHING];
  if (clothing != 0) {
    global const param* c = phys + clothing;
    const uint classes = (uint)c[PS_CLOTHING_CLASSES];
    const uint2 w = draw(seed, index, PS_STREAM_KNOB_DRAW, PS_DRAWN_CLOTHING).xy;
    const uint k = below(w.x, classes);
    d.outfit = (int)c[PS_CLOTHING_FIRST + k] + (int)below(w.y, (uint)c[PS_CLOTHING_FIRST + classes + k]);
    global const param* e = c + PS_CLOTHING_OUTFITS(classes) + (size_t)d.outfit * (size_t)c[PS_CLOTHING_STRIDE];
    d.shadow = (preal)e[PS_OUTFIT_SHADOW];
    if (c[PS_CLOTHING_FOLDS_HI] > 0) {
      const preal f = knob_draw((preal)c[PS_CLOTHING_FOLDS_LO], (preal)c[PS_CLOTHING_FOLDS_HI], seed, index,
                                PS_DRAWN_CLOTHING_FOLDS);
      d.fold = f * (preal)e[PS_OUTFIT_FOLD_K];
      d.fold_t = (preal)e[PS_OUTFIT_FOLD_T];
    }
    d.head = e + PS_OUTFIT_HEAD;
    d.moves = e + (int)e[PS_OUTFIT_MOVES];
  }
  if (d.at == 0) return d;
  global const param* b = phys + d.at;
  if (b[0] != 0) d.t = (preal)uniform24(draw(seed, index, PS_STREAM_KNOB_DRAW, PS_DRAWN_ILLUMINATION).x);
  d.w = knob_draw((preal)b[1], (preal)b[2], seed, index, PS_DRAWN_WORN_MINUTES);
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

kernel void stage_radiometry(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  global const uchar* base = base_row(atlas, bases, subject, &L, i, y);
  global preal* T = (global preal*)field + row0;
  const int s = subject[i];
  const SceneDraw scene = scene_draw(phys, seed, index);
  preal gain, offset, lv[PS_MAX_LAYERS];
  subject_kelvin(&scene, s, &gain, &offset);
  Layers Ly;
  composite_layers(&Ly, rec, &L, y);
  layer_values(&Ly, variant_values(&scene, L.subjects), &scene, L.subjects, lv);
  for (int x = 0; x < L.width; ++x) T[x] = lay_values(&Ly, atlas, x, lv, gray_kelvin(gain, (preal)base[x], offset));
  fold_values(&scene, fold_row(atlas, bases, subject, &L, i, y), T, L.width);
}
