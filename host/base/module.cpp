#include "base/module.h"

#include <dlfcn.h>

#include <filesystem>
#include <system_error>
#include <vector>

namespace portalsim {

namespace {
std::vector<std::filesystem::path> module_folders() {
  namespace fs = std::filesystem;
  std::vector<fs::path> folders;
  Dl_info info{};
  std::error_code ec;
  if (dladdr(reinterpret_cast<void*>(&module_folders), &info) && info.dli_fname && *info.dli_fname)
    folders.push_back(fs::absolute(info.dli_fname, ec).parent_path());
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    // In the binary itself, the object that holds this code is the executable.
    if (folders.empty() || folders.front() != exe.parent_path()) folders.push_back(exe.parent_path());
    folders.push_back((exe.parent_path() / PORTALSIM_MODULE_RELPATH).lexically_normal());
  }
  return folders;
}
}  // namespace

ModuleLoad open_module(const std::string& file) {
  ModuleLoad load;
  for (const std::filesystem::path& folder : module_folders()) {
    const std::string path = (folder / file).string();
    load.tried += (load.tried.empty() ? "" : ", ") + path;
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) continue;
    if (void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL)) {
      load.handle = handle;
      load.reason.clear();
      return load;
    }
    const char* why = dlerror();
    load.reason = why ? why : path + " did not load";
  }
  return load;
}

}  // namespace portalsim
