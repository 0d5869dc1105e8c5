// The physics model's IR camera, which sees the clothing surface. Stage "contact_shadow":
// the field is each object's surface dT alone, laid by its IR sprite's coverage over 0 K,
// against the surface it touches: on the body (a base image index of at least the
// subject's body_from) the skin (host: PS_PHYS_VARIANTS, -coupling (skin - object)), off
// it the room (phys_off_body), scaled to the subject's own skin (shadow_values); "heat_spread" then blurs it with the optics kernels. Stage "ir_surface": plus the bare body's surface temperature, the
// base image's index read as kelvin through the subject's (gain, offset).
// A row's layers' shadows for subject s, against the skin (`on`) and the room (`off`): each
// variant's (layer_values) times the subject's skin above the room over the catalogue's
// skin's (the object warms towards its carrier's skin; host: the off-body block's last S),
// times the outfit's factor (its insulation over the catalogue clothing's).
inline void shadow_values(const Layers* Ly, const PsViewLaunch* L, global const param* phys, const SceneDraw* d, int s,
                          preal* on, preal* off) {
  global const param* off_body = phys + L->phys_off_body;
  layer_values(Ly, variant_values(d, L->subjects), d, L->subjects, on);
  layer_values(Ly, off_body + L->subjects, d, L->subjects, off);
  const preal skin = (preal)off_body[L->subjects + L->variants + s] * d->shadow;
  for (int k = 0; k < Ly->count; ++k) {
    on[k] *= skin;
    off[k] *= skin;
  }
}

kernel void stage_contact_shadow(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  global preal* dT = (global preal*)field + row0;
  global const uchar* restrict base = base_row(atlas, bases, subject, &L, i, y);
  const int body_from = (int)phys[L.phys_off_body + subject[i]];
  const SceneDraw scene = scene_draw(phys, seed, index);
  preal on[PS_MAX_LAYERS], off[PS_MAX_LAYERS];
  Layers Ly;
  composite_layers(&Ly, rec, &L, y);
  shadow_values(&Ly, &L, phys, &scene, subject[i], on, off);
  for (int x = 0; x < L.width; ++x) dT[x] = lay_values(&Ly, atlas, x, (int)base[x] >= body_from ? on : off, (preal)0);
}

kernel void stage_ir_surface(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  global const uchar* restrict base = base_row(atlas, bases, subject, &L, i, y);
  global preal* restrict T = (global preal*)field + row0;
  const SceneDraw scene = scene_draw(phys, seed, index);
  preal gain, offset;
  subject_kelvin(&scene, subject[i], &gain, &offset);
  for (int x = 0; x < L.width; ++x) T[x] += gray_kelvin(gain, (preal)base[x], offset);
  fold_values(&scene, fold_row(atlas, bases, subject, &L, i, y), T, L.width);
}

// Stage "ir_netd": Gaussian noise of the IR NETD (kelvin rms) on every view pixel, a table
// Gaussian each from the counter generator (PS_STREAM_IR_NOISE, PS_GAUSS_ELEMENT), or the
// fast tier's draw (PS_FLAG_FAST_DRAWS). One work-item per scenario: fp32 builds draw 128
// pixels at a time (gauss128, ih128).
// The scenario's IR NETD: the knob's, or where it is drawn per scenario (PS_PHYS_NETD_HI
// above PS_PHYS_NETD), NETD + (hi - NETD) uniform24(word 0) of PS_STREAM_KNOB_DRAW (host:
// ir_netd_at).
inline preal ir_netd_of(global const param* phys, uint2 seed, ulong index) {
  return knob_draw((preal)phys[PS_PHYS_NETD], (preal)phys[PS_PHYS_NETD_HI], seed, index, PS_DRAWN_IR_NETD);
}

kernel void stage_ir_netd(VIEW_STAGE_ARGS) {
  VIEW_STAGE_SCENARIO;
  const preal sd = ir_netd_of(phys, seed, index);
  if (sd > 0)
    noise_cells((global preal*)field + (size_t)i * L.width * L.height, L.width * L.height, sd, seed, index,
                PS_STREAM_IR_NOISE, L.view, phys + L.phys_gauss, L.flags & PS_FLAG_FAST_DRAWS);
}

// Stage "ir_display": the IR display window, kelvin to temperature index 0..255 (as
// window_level), over pixels [a, b) of a view's T into o; fp32 builds 64 at a time.
inline void ir_window(global const preal* restrict T, global uchar* restrict o, global const param* phys, int a,
                      int b) {
  const preal lo = (preal)phys[PS_PHYS_WINDOW_MIN];
  const preal scale = (preal)255 / ((preal)phys[PS_PHYS_WINDOW_MAX] - lo);
  int p = a;
#if !defined(PRECISION_FP64)
  for (; p + 64 <= b; p += 64)
    store64(window_level16(vload16(0, T + p), lo, scale), window_level16(vload16(1, T + p), lo, scale),
            window_level16(vload16(2, T + p), lo, scale), window_level16(vload16(3, T + p), lo, scale), o + p);
  for (; p + 16 <= b; p += 16) store16(window_level16(vload16(0, T + p), lo, scale), o + p);
#endif
  for (; p < b; ++p) o[p] = window_level(T[p], lo, scale);
}

// One work-item per scenario: the view's pixels are one run in memory.
kernel void stage_ir_display(VIEW_STAGE_ARGS) {
  const uint i = (uint)get_global_id(0);
  if (i >= L.n) return;
  (void)atlas, (void)bases, (void)sprites, (void)places, (void)noise_offsets, (void)noise_gains, (void)subject,
      (void)objects, (void)alpha, (void)sigma, (void)records, (void)raw, (void)scratch;
  const int pixels = L.width * L.height;
  ir_window((global const preal*)field + (size_t)i * pixels, out + (size_t)i * pixels, phys, 0, pixels);
}
