// The flags that say what data set to make, shared by `generate` and `evaluate --spec`:
// --spec FILE, then --count, --seed, --rule, ..., every knob, each given flag over the
// file's key. One reading of them, so that both commands take the same words the same way.
#pragma once
#include <CLI/CLI.hpp>
#include <map>
#include <string>

#include "cli/common.h"
#include "schedule/run_spec.h"

namespace portalsim::cli {

struct SpecFlags {
  CommonOptions common;
  RunSpec spec;
  std::string count, spec_file, objects, pool, subjects, formats, png_level;
  BodyOptions body;  // --bodies, --body-count, --body-seed
  std::map<std::string, std::string> knobs;
  CLI::App* app = nullptr;
};

// Adds the common options, --spec and the data set's flags to `sub`; `outputs` adds the
// flags of what is written (--what, --format, --compress, --annotations, --image-format,
// --png-level, --scenarios), which evaluate leaves out: it writes features.
void add_spec_flags(CLI::App* sub, SpecFlags* o, bool outputs);

// The run the flags ask for: the --spec file, then the flags given over it; checked as
// RunSpec::validate checks it.
RunSpec build_spec(SpecFlags& o);

}  // namespace portalsim::cli
