// The data sets `portalsim validate` and `portalsim transfer` hand to WEKA: feature tables
// read from files or folders, checked against each other, written as ARFF in a scratch
// folder.
#pragma once
#include <set>
#include <string>

#include "cli/validate_tables.h"

namespace portalsim::cli {

// A table file (ARFF, CSV, data.h5), or a folder of scenario folders made into one (in
// `work`, named after `tag`) as `portalsim features` makes it. InputError naming the path.
Table load_table(const std::string& path, const std::string& work, const std::string& tag, int block,
                 const std::string& catalogue);

// Throws InputError naming the first attribute (file and line) where `a` and `b` differ.
void check_same_attributes(const Table& a, const Table& b);

// The table as ARFF with a class declaration shared by several sets, so WEKA sees one header.
void write_arff(const Table& t, const std::set<std::string>& classes, const std::string& path);

// A scratch folder for the tables handed to WEKA, removed on every way out.
struct WorkDir {
  std::string path;
  WorkDir();
  ~WorkDir();
  WorkDir(const WorkDir&) = delete;
  WorkDir& operator=(const WorkDir&) = delete;
};

}  // namespace portalsim::cli
