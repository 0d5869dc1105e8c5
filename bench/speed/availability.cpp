#include "speed/availability.h"

#include <iterator>

namespace portalsim::speed {

namespace {

// Each measure's JSON key and table title, in kMeasures' (the enum's) order.
struct MeasureNames {
  const char *key, *title;
};
constexpr MeasureNames kNames[] = {{"kernel", "kernel"},
                                   {"exact", "kernel, exact tier"},
                                   {"loop", "plain loop"},
                                   {"reference", "fp64 reference"},
                                   {"end_to_end", "end to end"}};
static_assert(std::size(kNames) == std::size(kMeasures) && [] {
  for (size_t i = 0; i < std::size(kMeasures); ++i)
    if (kMeasures[i] != static_cast<Measure>(i)) return false;
  return true;
}());

}  // namespace

const char* measure_key(Measure m) { return kNames[static_cast<size_t>(m)].key; }

const char* measure_title(Measure m) { return kNames[static_cast<size_t>(m)].title; }

std::string why_not(const SpeedPath& path, Measure m, const OpenCLDeviceInfo& device) {
  if (m == Measure::loop && !path.has_loop) return "no plain loop exists for this model";
  if (m == Measure::exact && !device.fp64) return "the exact tier computes in fp64, and the device has no cl_khr_fp64";
  if (m == Measure::end_to_end && path.needs_fp64_end_to_end && !device.fp64)
    return "generate --model physics computes the metal zones in fp64, and the device has no cl_khr_fp64";
  return "";
}

std::string fp64_note(const std::vector<SpeedPath>& paths, const OpenCLDeviceInfo& device) {
  if (device.fp64) return "";
  std::string all, partly;
  for (const SpeedPath& p : paths) {
    std::string missing;
    for (Measure m : kMeasures)
      if (m != Measure::exact && !why_not(p, m, device).empty() && (m != Measure::loop || p.has_loop))
        missing += std::string(missing.empty() ? "" : ", ") + measure_title(m);
    if (missing.empty())
      all += (all.empty() ? "" : ", ") + p.key;
    else
      partly += (partly.empty() ? "" : "; ") + p.key + " without " + missing;
  }
  std::string note = device.name +
                     " has no fp64 (cl_khr_fp64): the exact tier is not measured (it computes in fp64); "
                     "the fp64 reference runs on the host and is measured.\nPaths that run in full: " +
                     (all.empty() ? "none" : all) + ".";
  if (!partly.empty())
    note += "\nPaths that run in part: " + partly +
            " (generate --model physics computes the metal detector's zones in fp64).";
  return note;
}

}  // namespace portalsim::speed
