#include "backend/opencl/drivers.h"

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <vector>

#include "base/trim.h"

namespace portalsim {

namespace {
namespace fs = std::filesystem;

struct Driver {
  std::string icd;      // the .icd file that names it ("" where a variable names the library)
  std::string library;  // as written there
};

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? v : "";
}

// The library an .icd file names: its first line, without surrounding blanks; "" if none.
std::string named_library(const fs::path& icd) {
  std::ifstream in(icd);
  std::string line;
  std::getline(in, line);
  return trim(line);
}

// The drivers the loader would try, and where it looked (for the message when there are none).
std::vector<Driver> drivers(std::string& where) {
  const std::string vendors = env("OCL_ICD_VENDORS");
  const std::string vendor_path = env("OPENCL_VENDOR_PATH");
  const fs::path folder = !vendor_path.empty() ? fs::path(vendor_path) : fs::path("/etc/OpenCL/vendors");
  std::error_code ec;
  std::vector<Driver> found;
  if (!vendors.empty() && !fs::is_directory(vendors, ec)) {
    where = "OCL_ICD_VENDORS=" + vendors;
    if (vendors.size() > 4 && vendors.compare(vendors.size() - 4, 4, ".icd") == 0) {
      fs::path icd = vendors;
      if (vendors.find('/') == std::string::npos && fs::exists(folder / vendors, ec)) icd = folder / vendors;
      if (fs::is_regular_file(icd, ec)) found.push_back({icd.string(), named_library(icd)});
    } else {
      found.push_back({"", vendors});
    }
    return found;
  }
  const fs::path dir = !vendors.empty() ? fs::path(vendors) : folder;
  where = dir.string() + (!vendors.empty()       ? " (OCL_ICD_VENDORS)"
                          : !vendor_path.empty() ? " (OPENCL_VENDOR_PATH)"
                                                 : "");
  std::vector<fs::path> icds;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->path().extension() == ".icd") icds.push_back(it->path());
  std::sort(icds.begin(), icds.end());
  for (const fs::path& icd : icds) found.push_back({icd.string(), named_library(icd)});
  return found;
}
}  // namespace

DriverSearch search_opencl_drivers() {
  std::string where;
  const std::vector<Driver> all = drivers(where);
  if (all.empty())
    return {false, "no OpenCL driver is installed: " + where +
                       " holds no .icd file (on Debian, apt-get install pocl-opencl-icd for the CPU)"};
  std::string loaded;
  for (const Driver& d : all) {
    if (d.library.empty()) return {false, d.icd + " names no library on its first line, so its driver cannot load"};
    const std::string named = d.icd.empty() ? where : d.icd + " names " + d.library;
    dlerror();
    void* handle = dlopen(d.library.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* why = dlerror();
      return {false, named + ", which does not load: " + (why ? why : "unknown error")};
    }
    dlclose(handle);
    loaded += (loaded.empty() ? "" : ", ") + d.library;
  }
  return {true, "the drivers that " + where + " names load (" + loaded + ")"};
}

}  // namespace portalsim
