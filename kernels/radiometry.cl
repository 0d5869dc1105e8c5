// Stage "radiometry" (physics model): the scene as apparent temperature, in kelvin. The
// subject's base image turns into kelvin through its subject's (gain, offset); each object,
// in region order, covers it by its sprite's coverage c: v = c T_object + (1 - c) v, where
// T_object is the variant's apparent temperature under clothing (host: PS_PHYS_VARIANTS).

// Lays a row's objects over v at column x, each by its coverage, with its variant's value.
inline preal lay_values(const Layers* Ly, global const uchar* atlas, int x, global const param* value, preal v) {
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
    v = c * (preal)value[Ly->variant[k]] + ((preal)1 - c) * v;
  }
  return v;
}

kernel void stage_radiometry(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  global const uchar* base = base_row(atlas, bases, subject, &L, i, y);
  global preal* T = (global preal*)field + row0;
  const int s = subject[i];
  const preal gain = (preal)phys[PS_PHYS_SUBJECTS + 2 * s], offset = (preal)phys[PS_PHYS_SUBJECTS + 2 * s + 1];
  global const param* object_t = phys + PS_PHYS_VARIANTS(L.subjects);
  Layers Ly;
  composite_layers(&Ly, rec, &L, y);
  for (int x = 0; x < L.width; ++x) T[x] = lay_values(&Ly, atlas, x, object_t, gain * (preal)base[x] + offset);
}
