// One scenario's outputs as a folder, the layout of thesis appendix D.2 step 7:
// upper.png, lower.png (MMW), ir.png (IR through the palette), metal.txt, threat.txt,
// features.csv.
#pragma once
#include <string>

#include "assets/assets.h"
#include "backend/backend.h"
#include "sink/staging.h"

namespace portalsim {

struct FolderOptions {
  std::string image_format = "png";  // png or jpg
};

// Writes scenario i of `b` into `folder` (staged: nothing appears until commit).
void write_scenario_folder(StagedFolder& folder, const BatchOutput& b, size_t i, bool threat,
                           const Palette& palette, const FolderOptions& opt);

}  // namespace portalsim
