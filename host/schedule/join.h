// Joining parts of one data set (folders made with --shard i/k, here or anywhere) into
// the folder a single run makes, byte for byte: `portalsim merge`, and the last step of
// a generate launched by mpirun. Every output is a header plus rows in index order, so
// each part's rows land at an offset known from the parts' manifests; the ranks of a
// job copy their parts at those offsets in parallel on a shared filesystem.
#pragma once
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "schedule/ranks.h"

namespace portalsim {

struct Part {
  std::string dir;
  nlohmann::json manifest;
  uint64_t begin = 0, end = 0;  // the index range it holds
};

// Reads each folder's manifest.json and checks that the parts make one whole: the same
// version, catalogue and spec, and index ranges that neither overlap nor leave a gap.
// Returns them in index order. Throws InputError naming the part and what does not fit.
std::vector<Part> read_parts(const std::vector<std::string>& dirs);

struct JoinResult {
  uint64_t count = 0, positive = 0, negative = 0;
  uint64_t bytes = 0;  // of the joined outputs, images not counted
};

// Writes the whole data set into `out`, which exists, is empty and is held by the
// caller (rank 0's FolderLock). Collective: every rank calls it with the same parts.
// Rank r copies the parts whose position p has p % size == r (images are hard-linked
// where the filesystem allows, else copied); rank 0 writes the headers, builds data.h5
// and writes manifest.json last. Throws OutputError or InputError on every rank, with
// each failing rank's message, when any rank fails.
JoinResult join_parts(const std::vector<Part>& parts, const std::string& out, Ranks& ranks);

}  // namespace portalsim
