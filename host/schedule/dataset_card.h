// The two files that describe a finished data set, for people and for loaders:
//   README.md       a dataset card: YAML front matter (name, version, licence, the command
//                   that makes it again, spec, seed, counts and class balance, the sensor
//                   model and its parameters, each file and what it holds), then prose;
//   croissant.json  MLCommons Croissant 1.0 (JSON-LD): each file a FileObject (image folders
//                   FileSets), and RecordSets whose fields name the CSV or ARFF column, the
//                   data.h5 dataset, the .npy tensor or the JSON path they come from.
// Both come from the run's manifest and the headers of the files it names (no file is read
// past its header), so a single run, a merge and a ranked run write the same bytes: nothing
// in them depends on batch, threads, the folder's name, the host or the time.
#pragma once
#include <nlohmann/json.hpp>
#include <string>

namespace portalsim {

// Writes dir/README.md and dir/croissant.json (each to a temporary name, then renamed)
// for the finished run `manifest` describes; call it after every output has its final
// name and before manifest.json, which marks the folder finished. Throws OutputError or
// InputError naming the file.
void write_dataset_card(const std::string& dir, const nlohmann::json& manifest);

// The generate command that makes this data set again (batch and threads aside, which
// never change it); the output folder is written DIR.
std::string regenerate_command(const nlohmann::json& manifest);

}  // namespace portalsim
