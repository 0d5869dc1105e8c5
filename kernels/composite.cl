// Compositing (thesis algorithm steps 7-8): object sprites, alpha-blended over the
// subject's base image in region order. The host's plan gives each (variant, region)
// its sprite's top-left corner; these helpers work one image row at a time.

#define MAX_LAYERS 13

// Sprites: int4 (atlas offset, width, height, 0) per variant and sensor (0 MMW, 1 IR).
// Places: int4 (MMW x0, MMW y0, IR x0, IR y0) per variant and region.
typedef struct {
  int count;
  int offset[MAX_LAYERS];  // atlas offset of the sprite's row that meets this image row
  int x0[MAX_LAYERS];
  int width[MAX_LAYERS];
} Layers;

// Collects the sprites of regions [r_begin, r_end) that cross row y.
inline void composite_layers(Layers* L, global const short* objects, global const int4* sprites,
                             global const int4* places, int sensor, int r_begin, int r_end, int y) {
  L->count = 0;
  for (int r = r_begin; r < r_end; ++r) {
    const int v = objects[r];
    if (v < 0) continue;
    const int4 sp = sprites[v * 2 + sensor];
    const int4 pl = places[v * 13 + r];
    const int x0 = sensor ? pl.z : pl.x;
    const int y0 = sensor ? pl.w : pl.y;
    if (y < y0 || y >= y0 + sp.z) continue;
    const int k = L->count++;
    L->offset[k] = sp.x + (y - y0) * sp.y * 2;
    L->x0[k] = x0;
    L->width[k] = sp.y;
  }
}

// The composited value of pixel x over `base`: each layer through blend(), in region order.
inline real composite_pixel(const Layers* L, global const uchar* atlas, real base, int x, float alpha) {
  real v = base;
  for (int k = 0; k < L->count; ++k) {
    const int sx = x - L->x0[k];
    if (sx < 0 || sx >= L->width[k]) continue;
    const int o = L->offset[k] + 2 * sx;
    v = blend(v, atlas[o], atlas[o + 1], alpha);
  }
  return v;
}
