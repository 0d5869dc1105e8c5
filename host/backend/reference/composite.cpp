#include <algorithm>
#include <cmath>

#include "backend/reference/stages.h"
#include "scene/philox.h"

namespace portalsim::reference {

ViewScene view_scene(const Catalogue& cat, const AssetSet& assets, const ModelSettings& m, int view, const Scenario& s,
                     uint64_t index) {
  const Sensor& sensor = cat.sensors[view];
  ViewScene vs{cat, assets, m, sensor, view, s, index, {}};
  for (int r = 0; r < cat.region_count(); ++r) {
    const int16_t v = s.objects[r];
    if (v == kNoObject || !sensor.sees(r)) continue;
    const Image& sp = assets.sprite(sensor, v);
    const Rect rect = sensor.place(s.subject, r);
    const int x0 = rect.x + static_cast<int>(std::floor((rect.w - sp.width) / 2.0));
    const int y0 = rect.y + static_cast<int>(std::floor((rect.h - sp.height) / 2.0));
    double dx = 0, dy = 0;
    if (m.jitter > 0) {
      const Philox4 q = draw(m.seed, index, kStreamJitter, static_cast<uint32_t>(r));
      dx = m.jitter * sensor.jitter_scale_x * (2.0 * uniform24(q[0]) - 1.0);
      dy = m.jitter * sensor.jitter_scale_y * (2.0 * uniform24(q[1]) - 1.0);
    }
    vs.placed.push_back({&sp, x0, y0, dx, dy, v, object_transform(m, index, r)});
  }
  return vs;
}

// image = centre + scale R F (sprite - sprite centre), with R = [cos sin; -sin cos] (counter-
// clockwise in the image, whose y runs down) and F = diag(flip, 1); so sprite = sprite
// centre + F R^T (image - centre) / scale.
SpriteMap sprite_map(const Placed& p, bool bilinear) {
  const Image& sp = *p.sprite;
  SpriteMap m{};
  m.csx = (sp.width - 1) / 2.0;
  m.csy = (sp.height - 1) / 2.0;
  m.cx = p.x0 + (bilinear ? p.dx : std::floor(p.dx + 0.5)) + m.csx;
  m.cy = p.y0 + (bilinear ? p.dy : std::floor(p.dy + 0.5)) + m.csy;
  const double t = p.transform.rotation * (M_PI / 180.0);
  const double c = std::cos(t), s = std::sin(t), f = p.transform.flip ? -1.0 : 1.0, scale = p.transform.scale;
  m.a00 = f * c / scale;
  m.a01 = -f * s / scale;
  m.a10 = s / scale;
  m.a11 = c / scale;
  // The corners of the sprite's bilinear support, (-1, -1) .. (w, h), turned and scaled.
  double lo_x = m.cx, hi_x = m.cx, lo_y = m.cy, hi_y = m.cy;
  for (const double px : {-1.0 - m.csx, sp.width - m.csx})
    for (const double py : {-1.0 - m.csy, sp.height - m.csy}) {
      const double qx = f * px, qy = py;
      const double x = m.cx + scale * (c * qx + s * qy);
      const double y = m.cy + scale * (-s * qx + c * qy);
      lo_x = std::min(lo_x, x), hi_x = std::max(hi_x, x), lo_y = std::min(lo_y, y), hi_y = std::max(hi_y, y);
    }
  m.x0 = static_cast<int>(std::floor(lo_x)) - 1;
  m.y0 = static_cast<int>(std::floor(lo_y)) - 1;
  m.x1 = static_cast<int>(std::ceil(hi_x)) + 1;
  m.y1 = static_cast<int>(std::ceil(hi_y)) + 1;
  return m;
}

void SpriteMap::at(int x, int y, double& sx, double& sy) const {
  const double u = x - cx, v = y - cy;
  sx = csx + a01 * v + a00 * u;
  sy = csy + a11 * v + a10 * u;
}

void lay_objects(const ViewScene& vs, Field& f, double alpha,
                 double (*value)(const ViewScene&, const Placed&, int, int)) {
  const int W = f.width, H = f.height;
  for (const Placed& p : vs.placed) {
    const Image& sp = *p.sprite;
    if (vs.model.transforms()) {
      // Randomised objects: each pixel of the map's box samples the sprite point it maps to,
      // bilinearly on premultiplied coverage, as the sub-pixel branch below.
      const SpriteMap map = sprite_map(p, vs.model.bilinear);
      for (int y = std::max(0, map.y0); y <= std::min(H - 1, map.y1); ++y)
        for (int x = std::max(0, map.x0); x <= std::min(W - 1, map.x1); ++x) {
          double sx, sy;
          map.at(x, y, sx, sy);
          const int i0 = static_cast<int>(std::floor(sx)), j0 = static_cast<int>(std::floor(sy));
          const double tx = sx - i0, ty = sy - j0;
          double pv = 0, c = 0;
          for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 2; ++i) {
              const int ti = i0 + i, tj = j0 + j;
              if (ti < 0 || tj < 0 || ti >= sp.width || tj >= sp.height) continue;
              const double w = (i ? tx : 1 - tx) * (j ? ty : 1 - ty);
              const double cov = sp.at(ti, tj, 1) / 255.0;
              pv += w * cov * value(vs, p, ti, tj);
              c += w * cov;
            }
          if (c == 0) continue;
          double& v = f.at(x, y);
          v = (1.0 - alpha * c) * v + alpha * pv;
        }
      continue;
    }
    if (!vs.model.bilinear) {
      const int ox = p.x0 + static_cast<int>(std::floor(p.dx + 0.5));
      const int oy = p.y0 + static_cast<int>(std::floor(p.dy + 0.5));
      for (int sy = 0; sy < sp.height; ++sy)
        for (int sx = 0; sx < sp.width; ++sx) {
          const int x = ox + sx, y = oy + sy;
          if (x < 0 || y < 0 || x >= W || y >= H) continue;
          const double a = alpha * sp.at(sx, sy, 1) / 255.0;
          double& v = f.at(x, y);
          v = a * value(vs, p, sx, sy) + (1.0 - a) * v;
        }
      continue;
    }
    // Sub-pixel: the sprite's premultiplied value and coverage, sampled bilinearly.
    const double fx = p.x0 + p.dx, fy = p.y0 + p.dy;
    const auto texel = [&](int i, int j, double& pv, double& c) {
      if (i < 0 || j < 0 || i >= sp.width || j >= sp.height) return;
      const double cov = sp.at(i, j, 1) / 255.0;
      pv = cov * value(vs, p, i, j);
      c = cov;
    };
    for (int y = std::max(0, static_cast<int>(std::floor(fy)) - 1);
         y < std::min(H, static_cast<int>(fy) + sp.height + 2); ++y)
      for (int x = std::max(0, static_cast<int>(std::floor(fx)) - 1);
           x < std::min(W, static_cast<int>(fx) + sp.width + 2); ++x) {
        const double sx = x - fx, sy = y - fy;
        const int i0 = static_cast<int>(std::floor(sx)), j0 = static_cast<int>(std::floor(sy));
        const double tx = sx - i0, ty = sy - j0;
        double pv = 0, c = 0;
        for (int j = 0; j < 2; ++j)
          for (int i = 0; i < 2; ++i) {
            double tpv = 0, tc = 0;
            texel(i0 + i, j0 + j, tpv, tc);
            const double w = (i ? tx : 1 - tx) * (j ? ty : 1 - ty);
            pv += w * tpv;
            c += w * tc;
          }
        if (c == 0) continue;
        double& v = f.at(x, y);
        v = (1.0 - alpha * c) * v + alpha * pv;
      }
  }
}

// Thesis algorithm step 8: v = a s + (1 - a) v, a = alpha coverage / 255, objects in
// region order over the subject's base image.
void composite(const ViewScene& vs, Field& f) {
  const Image& base = vs.assets.bases[vs.scenario.subject][vs.view];
  const int W = base.width, H = base.height;
  f.width = W;
  f.height = H;
  f.v.assign(static_cast<size_t>(W) * H, 0.0);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) f.at(x, y) = base.at(x, y);
  lay_objects(vs, f, vs.cat.images.alpha,
              [](const ViewScene&, const Placed& p, int sx, int sy) { return double(p.sprite->at(sx, sy, 0)); });
}

}  // namespace portalsim::reference
