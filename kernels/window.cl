// Stage "window" (physics model): the MMW camera's automatic window, or its ends drawn per
// scenario. The raw grid's PS_WINDOW_LOW_PERMILLE and PS_WINDOW_HIGH_PERMILLE order
// statistics (the 1st and 99th percentiles; at least PS_WINDOW_MIN_SPAN kelvin apart), or
// the scenario's drawn ends (PS_WINDOW_DRAWN: drawn_window), are
// put on the fixed window's ends, so that stage_mmw_display shows them as gray 0 and 255, as
// a camera's automatic gain does per frame. The fixed window (PS_WINDOW_FIXED) leaves the
// grid. One work-item per scenario; the order statistics come from a copy in scratch, by
// Hoare's selection.

inline preal select_rank(global preal* restrict a, int n, int k) {
  int lo = 0, hi = n - 1;
  while (lo < hi) {
    const preal pivot = a[(lo + hi) / 2];
    int i = lo, j = hi;
    while (i <= j) {
      while (a[i] < pivot) ++i;
      while (a[j] > pivot) --j;
      if (i <= j) {
        const preal t = a[i];
        a[i++] = a[j];
        a[j--] = t;
      }
    }
    if (k <= j)
      hi = j;
    else if (k >= i)
      lo = i;
    else
      break;
  }
  return a[k];
}

kernel void stage_window(VIEW_STAGE_ARGS) {
  const uint i = (uint)get_global_id(0);
  if (i >= L.n || !L.window_auto) return;
  (void)atlas, (void)bases, (void)sprites, (void)places, (void)noise_offsets, (void)noise_gains, (void)subject,
      (void)objects, (void)alpha, (void)records, (void)field, (void)out;
  const int cells = L.raw_width * L.raw_height;
  global preal* restrict r = (global preal*)raw + (size_t)i * cells;
  const preal w0 = (preal)phys_common(phys)->window_min;
  preal lo, hi;
  if (L.window_auto == PS_WINDOW_DRAWN) {
    drawn_window(phys, (uint2)(L.seed_lo, L.seed_hi), scenario_index(indices, L.first_lo, L.first_hi, i), &lo, &hi);
  } else {
    global preal* restrict a = (global preal*)scratch + (size_t)i * cells;
    for (int k = 0; k < cells; ++k) a[k] = r[k];
    lo = select_rank(a, cells, PS_WINDOW_RANK(PS_WINDOW_LOW_PERMILLE, cells));
    hi = fmax(select_rank(a, cells, PS_WINDOW_RANK(PS_WINDOW_HIGH_PERMILLE, cells)), lo + (preal)PS_WINDOW_MIN_SPAN);
  }
  const preal gain = ((preal)phys_common(phys)->window_max - w0) / (hi - lo);
  for (int k = 0; k < cells; ++k) r[k] = w0 + (r[k] - lo) * gain;
}
