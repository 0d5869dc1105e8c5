// The physics model's IR camera, which sees the clothing surface. Stage "contact_shadow":
// the field is each object's surface dT alone (host: PS_PHYS_VARIANTS, -coupling (skin -
// object)), laid by its IR sprite's coverage over 0 K; "heat_spread" then blurs it with
// the optics kernels. Stage "ir_surface": plus the bare body's surface temperature, the
// base image's index read as kelvin through the subject's (gain, offset).
kernel void stage_contact_shadow(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  global preal* dT = (global preal*)field + row0;
  global const param* shadow = phys + PS_PHYS_VARIANTS(L.subjects);
  Layers Ly;
  composite_layers(&Ly, rec, &L, y);
  for (int x = 0; x < L.width; ++x) dT[x] = lay_values(&Ly, atlas, x, shadow, (preal)0);
}

kernel void stage_ir_surface(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  global const uchar* restrict base = base_row(atlas, bases, subject, &L, i, y);
  global preal* restrict T = (global preal*)field + row0;
  const int s = subject[i];
  const preal gain = (preal)phys[PS_PHYS_SUBJECTS + 2 * s], offset = (preal)phys[PS_PHYS_SUBJECTS + 2 * s + 1];
  for (int x = 0; x < L.width; ++x) T[x] += gain * (preal)base[x] + offset;
}

// Stage "ir_netd": Gaussian noise of the IR NETD (kelvin rms) on every view pixel, a table
// Gaussian each from the counter generator (PS_STREAM_IR_NOISE, PS_GAUSS_ELEMENT). One
// work-item per scenario: fp32 builds draw 128 pixels at a time (gauss128).
kernel void stage_ir_netd(VIEW_STAGE_ARGS) {
  VIEW_STAGE_SCENARIO;
  const preal sd = (preal)phys[PS_PHYS_NETD];
  if (sd > 0)
    gauss_cells_global((global preal*)field + (size_t)i * L.width * L.height, L.width * L.height, sd, true, seed, index,
                PS_STREAM_IR_NOISE, L.view, phys + L.phys_gauss);
}

// Stage "ir_display": the IR display window, kelvin to temperature index 0..255 (as
// window_level, its window read once: through restrict pointers the loop vectorises).
kernel void stage_ir_display(VIEW_STAGE_ARGS) {
  VIEW_STAGE_ROW;
  global const preal* restrict T = (global const preal*)field + row0;
  global uchar* restrict o = out + row0;
  const preal lo = (preal)phys[PS_PHYS_WINDOW_MIN];
  const preal scale = (preal)255 / ((preal)phys[PS_PHYS_WINDOW_MAX] - lo);
  for (int x = 0; x < L.width; ++x) o[x] = (uchar)clamp(floor((T[x] - lo) * scale + (preal)0.5), (preal)0, (preal)255);
}
