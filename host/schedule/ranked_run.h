// generate across the ranks of an MPI job (mpirun, srun): rank r makes the parts
// p = r, r + K, ... of the index range, each a resumable run of its own under
// DIR/.portalsim/parts/, then the ranks join them into DIR (join.h). The result is the
// data set one process makes, byte for byte. An interrupted or failed job resumes with
// --resume on any number of ranks, one included: the parts keep the split they began with.
#pragma once
#include <string>

#include "schedule/pipeline.h"
#include "schedule/ranks.h"

namespace portalsim {

// Whether `dir` holds the parts of a ranked run (finished or not).
bool has_ranked_parts(const std::string& dir);

// Collective. opt.shard must be 0/1 and opt.progress draws the whole job's progress on
// rank 0 (a line every few seconds when stderr is not a terminal). The result, the same
// on every rank, covers the whole job: done counts every rank's scenarios.
PipelineResult run_ranked(const RunSpec& spec, const Catalogue& cat, const AssetSet& assets, Backend& backend,
                          const std::string& dir, const PipelineOptions& opt, Ranks& ranks);

}  // namespace portalsim
