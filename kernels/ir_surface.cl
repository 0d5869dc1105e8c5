// The physics model's IR camera, which sees the clothing surface. Stage "contact_shadow":
// the field is each object's surface dT alone, laid by its IR sprite's coverage over 0 K,
// against the surface it touches: on the body (a base image index of at least the
// subject's body_from) the skin (host: PS_PHYS_VARIANTS, -coupling (skin - object)), off
// it the room (PsPhysTables.off_body), scaled to the subject's own skin (shadow_values); "heat_spread" then blurs it with the optics kernels. Stage "ir_surface": plus the bare body's surface temperature, the
// base image's index read as kelvin through the subject's (gain, offset).

kernel void stage_contact_shadow(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  global preal* dT = (global preal*)field + row0;
  global const uchar* restrict base = base_row(atlas, bases, subject, &L, i, y);
  const int body_from = (int)phys[L.tables.off_body + subject[i]];
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

kernel void stage_ir_netd(VIEW_STAGE_ARGS) {
  VIEW_STAGE_SCENARIO;
  const preal sd = ir_netd_of(phys, seed, index);
  if (sd > 0)
    noise_cells((global preal*)field + (size_t)i * L.width * L.height, L.width * L.height, sd, seed, index,
                PS_STREAM_IR_NOISE, L.view, phys + L.tables.gauss, L.flags & PS_FLAG_FAST_DRAWS);
}

// Stage "ir_display": the IR display window (ir_window), kelvin to temperature index
// 0..255. One work-item per scenario: the view's pixels are one run in memory.
kernel void stage_ir_display(VIEW_STAGE_ARGS) {
  const uint i = (uint)get_global_id(0);
  if (i >= L.n) return;
  (void)atlas, (void)bases, (void)sprites, (void)places, (void)noise_offsets, (void)noise_gains, (void)subject,
      (void)objects, (void)alpha, (void)records, (void)raw, (void)scratch;
  const int pixels = L.width * L.height;
  ir_window((global const preal*)field + (size_t)i * pixels, out + (size_t)i * pixels, phys, 0, pixels);
}
