// Stage "radiometry" (physics model): the scene as apparent temperature, in kelvin. The
// subject's base image turns into kelvin through its subject's (gain, offset); each object,
// in region order, covers it by its sprite's coverage c: v = c T_object + (1 - c) v, where
// T_object is the variant's apparent temperature under clothing (host: PS_PHYS_VARIANTS).

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
