// portalsim's optional modules: shared objects of its own, loaded (dlopen) only when a run
// needs what they link, so that the binary starts without those libraries. The OpenImageIO
// module (assets/oiio/codec.h) brings about 250 libraries; the MPI module
// (schedule/mpi/comm.h) links the system's Open MPI, which must be the launcher's own.
#pragma once
#include <dlfcn.h>

#include <string>

namespace portalsim {

struct ModuleLoad {
  void* handle = nullptr;  // never closed: a module's functions serve the whole process
  std::string tried;       // the files looked for, in order, comma-separated
  std::string reason;      // why the last one found did not load (the loader's message), or ""
};

// Looks for `file` (a file name) beside the object that holds this code (a build folder, the
// Python package), beside the executable, and where `cmake --install` puts the modules
// relative to bin/ (PORTALSIM_MODULE_RELPATH), and loads the first that loads.
ModuleLoad open_module(const std::string& file);

// The table of functions that the module `file` exports through its one entry point `entry`
// (a function returning `const Table*`), or null where it did not load (`load.reason` says
// why, "" where it was not found) or is from another build (a table whose `version` is not
// `version`).
template <class Table>
const Table* module_table(const std::string& file, const char* entry, int version, ModuleLoad& load) {
  load = open_module(file);
  if (!load.handle) return nullptr;
  using Entry = const Table* (*)();
  const auto f = reinterpret_cast<Entry>(dlsym(load.handle, entry));
  const Table* table = f ? f() : nullptr;
  if (table && table->version == version) return table;
  load.reason = "it is from another build of portalsim";
  return nullptr;
}

}  // namespace portalsim
