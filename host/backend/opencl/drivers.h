// Why the OpenCL ICD loader found no platform, told from the loader's own search: the
// loader (ocl-icd, Khronos's) drops a driver that fails to load without a word, so a driver
// built against a newer C++ runtime than the one loaded, or one missing a library, looks the
// same as no driver at all.
#pragma once
#include <string>

namespace portalsim {

struct DriverSearch {
  bool all_load = false;  // there are drivers and each loads: the problem is elsewhere
  std::string text;       // what the search found, for a message
};

// Follows ocl-icd's rules (libOpenCL(7)): OCL_ICD_VENDORS (a folder of .icd files, one .icd
// file, or a driver library), else OPENCL_VENDOR_PATH, else /etc/OpenCL/vendors; each .icd
// file names a driver library on its first line, which is loaded (dlopen) and closed again.
// Tells what it found: no .icd file at all (with what to install), the first driver that
// does not load (its .icd file, the library and the loader's message), or that every driver
// loads.
DriverSearch search_opencl_drivers();

}  // namespace portalsim
