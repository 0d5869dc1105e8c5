// Stage "radiometry" (physics model): the scene as apparent temperature, in kelvin. The
// subject's base image turns into kelvin through its subject's (gain, offset); each object,
// in region order, covers it by its sprite's coverage c: v = c T_object + (1 - c) v, where
// T_object is the variant's apparent temperature under clothing (host: PS_PHYS_VARIANTS).

// The illumination and worn time of a scenario where drawn per scenario (PS_PHYS_SCENE; host:
// illumination_at, worn_minutes_at): at, the scene block's offset (0: neither drawn); t, the
// illumination's place in its range (uniform24 of PS_DRAWN_ILLUMINATION's word 0); w, the
// worn time in minutes.
typedef struct {
  int at;
  preal t, w;
} SceneDraw;

inline SceneDraw scene_draw(global const param* phys, uint2 seed, ulong index) {
  SceneDraw d;
  d.at = (int)phys[PS_PHYS_SCENE];
  d.t = 0;
  d.w = 0;
  if (d.at == 0) return d;
  global const param* b = phys + d.at;
  if (b[0] != 0) d.t = (preal)uniform24(draw(seed, index, PS_STREAM_KNOB_DRAW, PS_DRAWN_ILLUMINATION).x);
  d.w = knob_draw((preal)b[1], (preal)b[2], seed, index, PS_DRAWN_WORN_MINUTES);
  return d;
}

// Subject s's (gain, offset) in the scenario: the view's, moved with the illumination.
inline void subject_kelvin(global const param* phys, const SceneDraw* d, int s, int subjects, preal* gain,
                           preal* offset) {
  *gain = (preal)phys[PS_PHYS_SUBJECTS + 2 * s];
  *offset = (preal)phys[PS_PHYS_SUBJECTS + 2 * s + 1];
  if (d->at == 0) return;
  global const param* b = phys + d->at + PS_SCENE_SUBJECTS + 2 * s;
  *gain += (preal)b[0] * d->t;
  *offset += (preal)b[1] * d->t;
}

// Each of a row's layers' value in the scenario: its variant's in `value`, moved where the
// illumination or the worn time is drawn.
inline void layer_values(const Layers* Ly, global const param* value, global const param* phys, const SceneDraw* d,
                         int subjects, preal* lv) {
  for (int k = 0; k < Ly->count; ++k) {
    lv[k] = (preal)value[Ly->variant[k]];
    if (d->at == 0) continue;
    global const param* v = phys + d->at + PS_SCENE_VARIANTS(subjects) + 4 * Ly->variant[k];
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

kernel void stage_radiometry(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  global const uchar* base = base_row(atlas, bases, subject, &L, i, y);
  global preal* T = (global preal*)field + row0;
  const int s = subject[i];
  const SceneDraw scene = scene_draw(phys, seed, index);
  preal gain, offset, lv[PS_MAX_LAYERS];
  subject_kelvin(phys, &scene, s, L.subjects, &gain, &offset);
  Layers Ly;
  composite_layers(&Ly, rec, &L, y);
  layer_values(&Ly, phys + PS_PHYS_VARIANTS(L.subjects), phys, &scene, L.subjects, lv);
  for (int x = 0; x < L.width; ++x) T[x] = lay_values(&Ly, atlas, x, lv, gain * (preal)base[x] + offset);
}
