// Metal zones under --model physics: the coil model of the reference
// (host/backend/reference/metal_physics.cpp), in fp64 with the reference's operations in
// the reference's order and no contraction into fma, so the integer zones match it
// exactly. One work-item per scenario. Needs cl_khr_fp64; the host checks for it.
#if defined(cl_khr_fp64)
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#pragma OPENCL FP_CONTRACT OFF

// Field of a dipole of moment (mx, 0, 0) at (cx, 0, cz), seen at (px, py, pz).
inline double3 metal_dipole(double mx, double cx, double cz, double px, double py, double pz) {
  const double rx = px - cx, ry = py - 0.0, rz = pz - cz;
  const double d2 = rx * rx + ry * ry + rz * rz;
  const double d = sqrt(d2);
  const double k = 3.0 * (mx * rx + 0.0 * ry + 0.0 * rz) / d2;
  const double den = PS_METAL_FOUR_PI * d2 * d;
  return (double3)((k * rx - mx) / den, (k * ry - 0.0) / den, (k * rz - 0.0) / den);
}

// One object's H_R^T M H_T in the zone of record zr: its PS_METAL_SEGMENTS dipoles along
// its long side (record M, PS_MV_*) about (px, py, pz), summed as the reference.
inline double metal_object_signal(global const double* zr, global const double* M, double px, double py, double pz) {
  double sum = 0.0;
  for (int k = 0; k < PS_METAL_SEGMENTS; ++k) {
    const double f = ((double)k + 0.5) / PS_METAL_SEGMENTS - 0.5;
    const double qx = px + f * M[PS_MV_LONG_X], qy = py + f * M[PS_MV_LONG_Y], qz = pz + f * M[PS_MV_LONG_Z];
    const double3 ht = metal_dipole(zr[PS_MZ_TX_M], zr[PS_MZ_TX_X], zr[PS_MZ_TX_Z], qx, qy, qz);
    const double3 hr = metal_dipole(zr[PS_MZ_RX_M], zr[PS_MZ_RX_X], zr[PS_MZ_RX_Z], qx, qy, qz);
    const double v0 = M[0] * ht.x + M[1] * ht.y + M[2] * ht.z;
    const double v1 = M[3] * ht.x + M[4] * ht.y + M[5] * ht.z;
    const double v2 = M[6] * ht.x + M[7] * ht.y + M[8] * ht.z;
    sum += hr.x * v0 + hr.y * v1 + hr.z * v2;
  }
  return sum / PS_METAL_SEGMENTS;
}

// A zone's deduction from its response gain |signal|: rounded half up, capped.
inline int metal_deduction(double t) {
  return t < PS_METAL_MAX_DEDUCTION ? (int)floor(t + 0.5) : PS_METAL_MAX_DEDUCTION;
}

kernel void metal_physics(global const double* zone_rec, global const double* region_rec,
                          global const double* tensors, global const uchar* base_zones, global const uchar* subject,
                          global const short* objects, uint n, uint2 seed, uint2 first, global const ulong* indices,
                          global const param* drawn, double jitter, double half_width, double scale,
                          double body_height, global uchar* out) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  const ulong index = scenario_index(indices, first.x, first.y, i);
  const int noise = metal_noise_of(drawn, seed, index);
  // Objects' positions (metres) and tensors, in region order as the reference.
  double px[PS_REGIONS], pz[PS_REGIONS];
  int variant[PS_REGIONS];
  int count = 0;
  for (int r = 0; r < PS_REGIONS; ++r) {
    const int v = objects[(size_t)i * PS_REGIONS + r];
    if (v < 0) continue;
    // The region's centre on this subject (its place moves with the subject's height).
    global const double* rr = region_rec + ((size_t)subject[i] * PS_REGIONS + r) * PS_MR_LEN;
    // The jitter of its placing view's composite, in that view's pixels.
    double dx = 0.0, dy = 0.0;
    if (jitter > 0.0) {
      const uint4 q = draw(seed, index, PS_STREAM_JITTER, (uint)r);
      dx = jitter * rr[PS_MR_JITTER_X] * (2.0 * ((double)(q.x >> 8) * (1.0 / 16777216.0)) - 1.0);
      dy = jitter * rr[PS_MR_JITTER_Y] * (2.0 * ((double)(q.y >> 8) * (1.0 / 16777216.0)) - 1.0);
    }
    const double col = rr[PS_MR_COL] + dx * rr[PS_MR_FIELD_PER_COL], row = rr[PS_MR_ROW] + dy * rr[PS_MR_FIELD_PER_ROW];
    px[count] = (col - half_width) * scale;
    pz[count] = body_height - row * scale;
    variant[count] = v;
    ++count;
  }
  global const uchar* base = base_zones + (size_t)subject[i] * PS_ZONES;
  for (int z = 0; z < PS_ZONES; ++z) {
    global const double* zr = zone_rec + z * PS_MZ_LEN;
    double signal = 0.0;
    for (int o = 0; o < count; ++o)
      signal += metal_object_signal(zr, tensors + (size_t)variant[o] * PS_MV_LEN, px[o], 0.0, pz[o]);
    const int deduction = metal_deduction(zr[PS_MZ_GAIN] * fabs(signal));
    int value = (int)base[z] - deduction;
    if (noise > 0 && deduction > 0) {
      const uint4 r = draw(seed, index, PS_STREAM_METAL_NOISE, (uint)z);
      value += (int)below(r.x, (uint)noise + 1u) - (int)below(r.y, (uint)noise + 1u);
    }
    out[(size_t)i * PS_ZONES + z] = (uchar)clamp(value, 1, 200);
  }
}

// A metal map's probes (host/evaluate/metal_map.h): one object alone at each probe's place
// (PS_MP_*), its record (PS_MV_*) in `objects`. Writes each zone's response gain |signal|
// (unrounded) and deduction, as reference::metal_response. One work-item per probe.
kernel void metal_map(global const double* zone_rec, global const double* objects, global const double* probes,
                      uint n, global double* response, global uchar* deduction) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  global const double* p = probes + (size_t)i * PS_MP_LEN;
  global const double* M = objects + (size_t)p[PS_MP_OBJECT] * PS_MV_LEN;
  for (int z = 0; z < PS_ZONES; ++z) {
    global const double* zr = zone_rec + z * PS_MZ_LEN;
    const double t = zr[PS_MZ_GAIN] * fabs(metal_object_signal(zr, M, p[PS_MP_X], p[PS_MP_Y], p[PS_MP_Z]));
    response[(size_t)i * PS_ZONES + z] = t;
    deduction[(size_t)i * PS_ZONES + z] = (uchar)metal_deduction(t);
  }
}
#endif
