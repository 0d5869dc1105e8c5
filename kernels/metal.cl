// Zone-metal accumulation (thesis algorithm step 2): each object's 19-zone influence,
// looked up by its metal category and region, is summed and subtracted from the
// subject's base values, then clamped to [1, 200]. Integer arithmetic throughout, so it
// matches the reference exactly. One work-item per scenario.

kernel void metal_zones(global const uchar* influence, global const uchar* variant_category,
                        global const uchar* base_zones, global const uchar* subject, global const short* objects,
                        uint n, uint2 seed, uint2 first, global const ulong* indices, global const param* drawn,
                        global uchar* out) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  const ulong index = scenario_index(indices, first.x, first.y, i);
  const int noise = metal_noise_of(drawn, seed, index);
  int sum[PS_ZONES];
  for (int z = 0; z < PS_ZONES; ++z) sum[z] = 0;
  for (int r = 0; r < PS_REGIONS; ++r) {
    const int v = objects[(size_t)i * PS_REGIONS + r];
    if (v < 0) continue;
    global const uchar* row = influence + ((size_t)variant_category[v] * PS_REGIONS + r) * PS_ZONES;
    for (int z = 0; z < PS_ZONES; ++z) sum[z] += row[z];
  }
  global const uchar* base = base_zones + (size_t)subject[i] * PS_ZONES;
  for (int z = 0; z < PS_ZONES; ++z) {
    int value = (int)base[z] - sum[z];
    if (noise > 0 && sum[z] > 0) {
      const uint4 r = draw(seed, index, PS_STREAM_METAL_NOISE, (uint)z);
      value += (int)below(r.x, (uint)noise + 1u) - (int)below(r.y, (uint)noise + 1u);
    }
    out[(size_t)i * PS_ZONES + z] = (uchar)clamp(value, 1, 200);
  }
}
