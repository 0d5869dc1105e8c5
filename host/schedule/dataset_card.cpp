#include "schedule/dataset_card.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "base/error.h"
#include "io/table_fields.h"
#include "plan/knobs.h"
#include "schedule/run_spec.h"
#include "sink/h5_file.h"
#include "sink/sink_kinds.h"
#include "sink/sinks.h"
#include "sink/staging.h"

namespace portalsim {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The portal a data set was made with, as its manifest records the catalogue
// (pipeline.cpp, run_identity: catalogue.portal).
struct Portal {
  struct View {
    std::string name, camera, side;
    bool pooled = false;
    std::string own_camera;  // "NETD 4 K, raw grid 24x24": its own camera's numbers, if any
  };
  std::vector<View> views;
  int regions = 0, zones = 0;

  static Portal of(const json& manifest) {
    const json& p = manifest.at("catalogue").at("portal");
    Portal out;
    for (const json& v : p.at("views")) {
      View view{v.at("name"), v.at("camera"), v.at("side"), v.at("pooled").get<bool>(), ""};
      if (v.contains("netd")) view.own_camera = "NETD " + json(v.at("netd").get<double>()).dump() + " K";
      if (v.contains("raw"))
        view.own_camera +=
            (view.own_camera.empty() ? "" : ", ") + std::string("raw grid ") + v.at("raw").get<std::string>();
      out.views.push_back(std::move(view));
    }
    out.regions = p.at("regions").get<int>();
    out.zones = p.at("zones").get<int>();
    return out;
  }
  const View* view(const std::string& name) const {
    for (const View& v : views)
      if (v.name == name) return &v;
    return nullptr;
  }
  // The names of the views of one camera (or the pooled ones), comma-separated.
  std::string names(const std::string& camera, bool pooled_only = false) const {
    std::string out;
    for (const View& v : views)
      if ((camera.empty() || v.camera == camera) && (!pooled_only || v.pooled))
        out += (out.empty() ? "" : ", ") + v.name;
    return out;
  }
  // "passive millimetre-wave camera views (upper, back_upper), infrared camera views (ir)".
  std::string camera_views() const {
    std::string out;
    for (const auto& [camera, what] : {std::pair{"mmw", "passive millimetre-wave"}, std::pair{"ir", "infrared"}})
      if (const std::string n = names(camera); !n.empty())
        out += (out.empty() ? "" : ", ") + std::string(what) + " camera views (" + n + ")";
    return out;
  }
  // The thesis's portal: front MMW views upper and lower (pooled), a front IR view ir.
  bool thesis_cameras() const {
    return names("mmw") == "upper, lower" && names("ir") == "ir" && names("", true) == "upper, lower" &&
           view("upper")->side == "front" && view("lower")->side == "front" && view("ir")->side == "front";
  }
};

// What each tensor holds (data.h5's datasets and the .npy tensors share names).
std::string tensor_meaning(const std::string& name, const Portal& portal) {
  const std::string R = std::to_string(portal.regions);
  if (name == "metal")
    return "metal detector: " + std::to_string(portal.zones) + " zone values, 200 nothing, lower more metal";
  if (name == "features")
    return portal.thesis_cameras()
               ? "image features: block means of the upper then lower MMW view, then region means (names in its "
                 "columns attribute)"
               : "image features: block means of each pooled view in turn (" + portal.names("", true) +
                     "), then region means (names in its columns attribute)";
  static const std::map<std::string, std::string> m{
      {"label", "1 = threat, 0 = not"},
      {"subject", "the subject, 1-based; 0 where every scenario has its own body (scenarios.csv records each)"},
      {"region_orientation", "per region: the drawing's index (object_drawings: h, v), -1 none"},
      {"region_label", "per region: the rule applied to that region's object alone"},
      {"region_rotation", "per region: the object's angle in degrees, counter-clockwise (0 where empty)"},
      {"region_scale", "per region: the object's scale factor (1 where empty)"},
      {"region_flip", "per region: 1 where the object is mirrored left to right"},
      {"clothing_outfit",
       "per scenario: its outfit's index in the run's outfit table (docs/model/clothing.md; "
       "scenarios.csv names it)"},
      {"clothing_transmission", "per scenario: its outfit's power transmission at 94 GHz"},
      {"clothing_clo", "per scenario: its outfit's thermal insulation, clo"},
      {"mmw_raw_width", "per scenario: the MMW camera's raw grid, cells across (drawn from the run's --mmw-raw list)"},
      {"mmw_raw_height", "per scenario: the MMW camera's raw grid, cells down (drawn from the run's --mmw-raw list)"},
  };
  if (const auto it = m.find(name); it != m.end()) return it->second;
  if (name.starts_with("param_"))
    return "per scenario: the value the knob " + name.substr(6) +
           " was drawn for it (uniform over the run's A..B; the manifest gives the range)";
  if (name == "region_object")
    return "per region 1-" + R + ": the object's index in the catalogue (object_names), -1 none";
  const bool mask = name.starts_with("mask_"), index = name.ends_with("_index");
  const std::string stem = mask ? name.substr(5) : index ? name.substr(0, name.size() - 6) : name;
  const Portal::View* v = portal.view(stem);
  if (!v) return "per-scenario tensor " + name;
  const bool mmw = v->camera == "mmw", back = v->side == "back";
  if (mask)
    return "instance mask of the " + (mmw || stem != "ir" ? stem + " " : std::string()) + (mmw ? "MMW" : "IR") +
           " view: each pixel the region (1-" + R + ") whose object owns it, 0 none";
  const std::string camera = std::string(mmw ? "MMW" : "IR") + " camera";
  const std::string which = (stem == "upper" || stem == "lower") && mmw && !back ? ", " + stem + " body"
                            : stem == "ir" && !mmw && !back                      ? ""
                                                            : ", view " + stem + (back ? " (the back)" : "");
  if (index) return camera + which + ": the temperature index (0-255) before the palette";
  return camera + which + (mmw ? ": 8-bit gray" : ": RGB through the palette");
}

// What each file of a data set holds.
// What a file holds: its sink kind's words (sink/sink_kinds.h), or the card's for its own
// files and for tensors.
std::string file_meaning(const std::string& name, const Portal& portal) {
  if (const SinkKind* k = sink_kind_of(name); k && k->meaning)
    if (std::string m = k->meaning(name, portal.regions, portal.zones); !m.empty()) return m;
  const std::map<std::string, std::string> m{
      {"manifest.json",
       "the run's identity (version, catalogue, spec, shard), counts, and each file's size and "
       "XXH3-64"},
      {"README.md", "this dataset card"},
      {"croissant.json", "the MLCommons Croissant description of these files and their fields"},
  };
  if (const auto it = m.find(name); it != m.end()) return it->second;
  if (name.ends_with(".npy")) return "tensor: " + tensor_meaning(name.substr(0, name.size() - 4), portal);
  return "an output of portalsim generate";
}

std::string encoding_of(const std::string& name) {
  const std::string ext = fs::path(name).extension().string();
  if (ext == ".csv") return "text/csv";
  if (ext == ".arff") return "text/x-arff";
  if (ext == ".json") return "application/json";
  if (ext == ".h5") return "application/x-hdf5";
  if (ext == ".npy") return "application/x-npy";
  if (ext == ".png") return "image/png";
  if (ext == ".jpg") return "image/jpeg";
  return "text/plain";
}

std::ifstream open_input(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw OutputError(p.string() + ": cannot read (to describe it in croissant.json)");
  return in;
}

// The first line of a text file (a CSV's header), without its line end.
std::string first_line(const fs::path& p) {
  std::ifstream in = open_input(p);
  std::string line;
  std::getline(in, line);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return line;
}

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> out;
  size_t at = 0;
  while (true) {
    const size_t next = text.find(sep, at);
    out.push_back(text.substr(at, next == std::string::npos ? std::string::npos : next - at));
    if (next == std::string::npos) return out;
    at = next + 1;
  }
}

// An ARFF file's attribute names, in order, read up to @data.
std::vector<std::string> arff_attributes(const fs::path& p) {
  std::ifstream in = open_input(p);
  std::vector<std::string> names;
  size_t n = 0;
  for (std::string line; std::getline(in, line);) {
    ++n;
    if (line.starts_with("@data")) break;
    if (!line.starts_with("@attribute ")) continue;
    names.push_back(io::arff_attribute(line, p.string(), n).name);
  }
  return names;
}

// A CSV file's column names: its header's fields.
std::vector<std::string> csv_columns(const fs::path& p) {
  return io::split_fields(first_line(p), io::Quoting::csv, p.string(), 1);
}

std::vector<std::string> lines_of(const fs::path& p) {
  std::ifstream in = open_input(p);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) out.push_back(line);
  return out;
}

// An .npy file's element type ("<f4") and shape, from its header.
struct NpyHeader {
  std::string descr;
  std::vector<uint64_t> shape;
};

NpyHeader npy_header_of(const fs::path& p) {
  std::ifstream in = open_input(p);
  char pre[12] = {};
  in.read(pre, sizeof pre);
  if (!in || std::memcmp(pre, "\x93NUMPY", 6) != 0) throw InputError(p.string() + ": not an .npy file");
  const bool v1 = pre[6] == 1;
  const auto byte = [&](int i) { return static_cast<uint64_t>(static_cast<unsigned char>(pre[i])); };
  const uint64_t len = v1 ? byte(8) | byte(9) << 8 : byte(8) | byte(9) << 8 | byte(10) << 16 | byte(11) << 24;
  in.seekg(v1 ? 10 : 12);
  std::string h(static_cast<size_t>(std::min<uint64_t>(len, 1 << 16)), '\0');
  in.read(h.data(), static_cast<std::streamsize>(h.size()));
  NpyHeader out;
  const size_t d = h.find("'descr': '"), s = h.find("'shape': (");
  if (!in || d == std::string::npos || s == std::string::npos)
    throw InputError(p.string() + ": unreadable .npy header");
  out.descr = h.substr(d + 10, h.find('\'', d + 10) - (d + 10));
  for (const std::string& n : split(h.substr(s + 10, h.find(')', s) - (s + 10)), ','))
    if (n.find_first_of("0123456789") != std::string::npos) out.shape.push_back(std::stoull(n));
  return out;
}

std::string data_type_of_descr(const std::string& descr) {
  return descr.find('f') != std::string::npos ? "sc:Float" : "sc:Integer";
}

std::string data_type_of(TensorType t) {
  return t == TensorType::f32 || t == TensorType::f64 ? "sc:Float" : "sc:Integer";
}

std::string shape_text(const std::vector<uint64_t>& dims) {
  std::string s;
  for (uint64_t d : dims) {
    if (!s.empty()) s += ',';
    s += std::to_string(d);
  }
  return s;
}

// A Croissant field read from a file object's column (a CSV or ARFF column, a data.h5
// dataset, or the tensor of an .npy file, whose rows are the records).
json column_field(const std::string& set, const std::string& name, const std::string& file, const std::string& column,
                  const std::string& type, const std::string& description = "") {
  json f{{"@type", "cr:Field"},
         {"@id", set + "/" + name},
         {"name", name},
         {"dataType", type},
         {"source", {{"fileObject", {{"@id", file}}}, {"extract", {{"column", column}}}}}};
  if (!description.empty()) f["description"] = description;
  return f;
}

// A per-record array: its shape after the record axis (Croissant's isArray, arrayShape).
void mark_array(json& field, const std::vector<uint64_t>& per_row) {
  if (per_row.empty()) return;
  field["isArray"] = true;
  field["arrayShape"] = shape_text(per_row);
}

json record_set(const std::string& id, const std::string& description, json fields) {
  return {
      {"@type", "cr:RecordSet"}, {"@id", id}, {"name", id}, {"description", description}, {"field", std::move(fields)}};
}

// A field of a COCO array's records, by JSON path.
json coco_field(const std::string& set, const std::string& array, const std::string& key, const std::string& type,
                bool repeated = false) {
  json f{{"@type", "cr:Field"},
         {"@id", set + "/" + key},
         {"name", key},
         {"dataType", type},
         {"source",
          {{"fileObject", {{"@id", "annotations.json"}}}, {"extract", {{"jsonPath", "$." + array + "[*]." + key}}}}}};
  if (repeated) f["repeated"] = true;
  return f;
}

json coco_record_sets() {
  json categories = json::array(), images = json::array(), anns = json::array();
  for (const auto& [k, t] : std::vector<std::pair<const char*, const char*>>{
           {"id", "sc:Integer"}, {"name", "sc:Text"}, {"supercategory", "sc:Text"}})
    categories.push_back(coco_field("coco_categories", "categories", k, t));
  for (const auto& [k, t] : std::vector<std::pair<const char*, const char*>>{{"id", "sc:Integer"},
                                                                             {"file_name", "sc:Text"},
                                                                             {"width", "sc:Integer"},
                                                                             {"height", "sc:Integer"},
                                                                             {"scenario", "sc:Integer"},
                                                                             {"view", "sc:Text"}})
    images.push_back(coco_field("coco_images", "images", k, t));
  for (const auto& [k, t] : std::vector<std::pair<const char*, const char*>>{{"id", "sc:Integer"},
                                                                             {"image_id", "sc:Integer"},
                                                                             {"category_id", "sc:Integer"},
                                                                             {"area", "sc:Integer"},
                                                                             {"iscrowd", "sc:Integer"},
                                                                             {"region", "sc:Integer"},
                                                                             {"orientation", "sc:Text"},
                                                                             {"dx", "sc:Float"},
                                                                             {"dy", "sc:Float"},
                                                                             {"rotation", "sc:Float"},
                                                                             {"scale", "sc:Float"},
                                                                             {"flip", "sc:Boolean"}})
    anns.push_back(coco_field("coco_annotations", "annotations", k, t));
  anns.push_back(coco_field("coco_annotations", "annotations", "bbox", "sc:Float", true));
  anns.push_back(coco_field("coco_annotations", "annotations", "segmentation.counts", "sc:Integer", true));
  anns.push_back(coco_field("coco_annotations", "annotations", "segmentation.size", "sc:Integer", true));
  return json::array(
      {record_set("coco_categories", "COCO categories: the catalogue's objects, ids from 1", categories),
       record_set("coco_images", "COCO images: one per scenario and camera view", images),
       record_set("coco_annotations",
                  "COCO annotations: each visible object's box [x, y, w, h], area, run-length mask (column-major), "
                  "region and random transform",
                  anns)});
}

// Croissant 1.0's context, with 1.1's array properties for the tensors.
json croissant_context() {
  return {{"@language", "en"},
          {"@vocab", "https://schema.org/"},
          {"arrayShape", "cr:arrayShape"},
          {"citeAs", "cr:citeAs"},
          {"column", "cr:column"},
          {"conformsTo", "dct:conformsTo"},
          {"cr", "http://mlcommons.org/croissant/"},
          {"rai", "http://mlcommons.org/croissant/RAI/"},
          {"data", {{"@id", "cr:data"}, {"@type", "@json"}}},
          {"dataType", {{"@id", "cr:dataType"}, {"@type", "@vocab"}}},
          {"dct", "http://purl.org/dc/terms/"},
          {"examples", {{"@id", "cr:examples"}, {"@type", "@json"}}},
          {"extract", "cr:extract"},
          {"field", "cr:field"},
          {"fileProperty", "cr:fileProperty"},
          {"fileObject", "cr:fileObject"},
          {"fileSet", "cr:fileSet"},
          {"format", "cr:format"},
          {"includes", "cr:includes"},
          {"isArray", "cr:isArray"},
          {"isLiveDataset", "cr:isLiveDataset"},
          {"jsonPath", "cr:jsonPath"},
          {"key", "cr:key"},
          {"md5", "cr:md5"},
          {"parentField", "cr:parentField"},
          {"path", "cr:path"},
          {"recordSet", "cr:recordSet"},
          {"references", "cr:references"},
          {"regex", "cr:regex"},
          {"repeated", "cr:repeated"},
          {"replace", "cr:replace"},
          {"sc", "https://schema.org/"},
          {"separator", "cr:separator"},
          {"source", "cr:source"},
          {"subField", "cr:subField"},
          {"transform", "cr:transform"}};
}

const char* const kBuiltInCatalogue = "<built-in catalogue>";

std::string shell_quote(const std::string& s) {
  if (!s.empty() && s.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_.,/:=+-") ==
                        std::string::npos)
    return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string data_set_name(const json& m) {
  const json& s = m["spec"];
  const std::string rule = s.value("rule", "");
  return "portalsim " + s.value("model", "thesis") + " model, " + s.value("what", "features") + ", " +
         (rule.empty() ? "no rule" : "rule " + rule) + ", seed " + s.value("seed", "0") + ", " +
         std::to_string(m.value("count", uint64_t{0})) + " scenarios";
}

// The sensor model's parameters: every knob of the run's identity but the model's name.
json model_parameters(const json& spec) {
  json p = json::object();
  p["tier"] = spec.value("tier", "standard");
  for (const Knob& k : knobs())
    if (k.identity && k.key != "model" && spec.contains(k.key)) p[k.key] = spec[k.key];
  return p;
}

struct Description {
  Portal portal;
  json distribution = json::array();
  json record_sets = json::array();
  json files = json::array();  // for the card: name, bytes, xxh3_64, holds
};

void add_file(Description& d, const std::string& name, const json& recorded) {
  json fo{{"@type", "cr:FileObject"},
          {"@id", name},
          {"name", name},
          {"contentUrl", name},
          {"encodingFormat", encoding_of(name)},
          {"description", file_meaning(name, d.portal)}};
  json card{{"name", name}, {"holds", file_meaning(name, d.portal)}};
  if (recorded.is_object()) {
    fo["contentSize"] = std::to_string(recorded.at("bytes").get<uint64_t>()) + " B";
    card["bytes"] = recorded.at("bytes");
    card["xxh3_64"] = recorded.at("xxh3_64");
  }
  d.distribution.push_back(std::move(fo));
  d.files.push_back(std::move(card));
}

void describe_table(Description& d, const fs::path& dir, const std::string& name) {
  const std::string set = fs::path(name).stem().string() + "_" + fs::path(name).extension().string().substr(1);
  json fields = json::array();
  if (name.ends_with(".csv")) {
    for (const std::string& c : csv_columns(dir / name))
      fields.push_back(column_field(set, c, name, c, c == "subject" || c == "index" ? "sc:Integer" : "sc:Text"));
    if (name == "features.csv")
      for (json& f : fields) f["dataType"] = f["name"] == "class" ? "sc:Text" : "sc:Float";
  } else if (name.ends_with(".arff")) {
    for (const std::string& c : arff_attributes(dir / name))
      fields.push_back(column_field(set, c, name, c, c == "class" ? "sc:Text" : "sc:Float"));
  } else {  // features.npy: a matrix whose columns features.columns.txt names
    const std::string names = fs::path(name).stem().string() + ".columns.txt";
    for (const std::string& c : lines_of(dir / names)) fields.push_back(column_field(set, c, name, c, "sc:Float"));
  }
  d.record_sets.push_back(record_set(set, file_meaning(name, d.portal), std::move(fields)));
}

void describe_h5(Description& d, const fs::path& dir) {
  const H5Layout h5 = read_h5_layout((dir / "data.h5").string());
  json fields = json::array();
  for (const H5Dataset& ds : h5.datasets) {
    json f =
        column_field("data_h5", ds.name, "data.h5", ds.name, data_type_of(ds.type), tensor_meaning(ds.name, d.portal));
    mark_array(f, ds.dims);
    fields.push_back(std::move(f));
  }
  d.record_sets.push_back(record_set(
      "data_h5", "one record per scenario: row i of every dataset of data.h5 (each field's column is its dataset)",
      std::move(fields)));
}

// The tensors written as .npy files (--what images --format npy): one record per scenario.
void describe_npy_tensors(Description& d, const fs::path& dir, const std::vector<std::string>& names) {
  json fields = json::array();
  for (const std::string& n : names) {
    const std::string stem = n.substr(0, n.size() - 4);
    const NpyHeader h = npy_header_of(dir / n);
    json f = column_field("tensors", stem, n, stem, data_type_of_descr(h.descr), tensor_meaning(stem, d.portal));
    mark_array(f, std::vector<uint64_t>(h.shape.begin() + (h.shape.empty() ? 0 : 1), h.shape.end()));
    fields.push_back(std::move(f));
  }
  if (!fields.empty())
    d.record_sets.push_back(record_set(
        "tensors", "one record per scenario: row i of each .npy tensor (each field's column is its file's stem)",
        std::move(fields)));
}

// images/<index>/: one FileSet and one RecordSet per kind of file in a scenario's folder.
void describe_image_folders(Description& d, const fs::path& dir, uint64_t first) {
  const fs::path one = dir / "images" / image_folder_name(first);
  std::vector<std::string> kinds;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(one, ec))
    if (e.is_regular_file()) kinds.push_back(e.path().filename().string());
  if (ec) throw OutputError(one.string() + ": cannot list (to describe it in croissant.json): " + ec.message());
  std::sort(kinds.begin(), kinds.end());
  for (const std::string& k : kinds) {
    const std::string id = "images/*/" + k,
                      set = "images_" + fs::path(k).stem().string() + "_" + fs::path(k).extension().string().substr(1);
    const bool image = encoding_of(k).starts_with("image/");
    d.distribution.push_back({{"@type", "cr:FileSet"},
                              {"@id", id},
                              {"name", id},
                              {"encodingFormat", encoding_of(k)},
                              {"includes", id},
                              {"description", "each scenario's " + k + " (images/<index>/, index zero-padded to 8)"}});
    json scenario{{"@type", "cr:Field"},
                  {"@id", set + "/scenario"},
                  {"name", "scenario"},
                  {"dataType", "sc:Integer"},
                  {"source",
                   {{"fileSet", {{"@id", id}}},
                    {"extract", {{"fileProperty", "filepath"}}},
                    {"transform", {{"regex", "^images/([0-9]+)/"}}}}}};
    json content{{"@type", "cr:Field"},
                 {"@id", set + "/content"},
                 {"name", "content"},
                 {"dataType", image ? "sc:ImageObject" : "sc:Text"},
                 {"source", {{"fileSet", {{"@id", id}}}, {"extract", {{"fileProperty", "content"}}}}}};
    d.record_sets.push_back(
        record_set(set, "each scenario's " + k, json::array({std::move(scenario), std::move(content)})));
  }
  d.files.push_back(
      {{"name", "images/"}, {"holds", "one folder per scenario, images/<index>/, as simulate writes it"}});
}

Description describe(const fs::path& dir, const json& manifest) {
  Description d;
  d.portal = Portal::of(manifest);
  std::vector<std::string> npy_tensors;
  for (const json& o : manifest.at("outputs")) {
    const std::string n = o.at("name").get<std::string>();
    add_file(d, n, o);
    if (n == "data.h5")
      describe_h5(d, dir);
    else if (n == "annotations.json")
      for (const json& rs : coco_record_sets()) d.record_sets.push_back(rs);
    else if (n.starts_with("features.") || n == "scenarios.csv")
      describe_table(d, dir, n);
    else if (n.ends_with(".npy"))
      npy_tensors.push_back(n);
  }
  describe_npy_tensors(d, dir, npy_tensors);
  if (std::error_code ec; fs::exists(dir / "features.columns.txt", ec)) add_file(d, "features.columns.txt", json());
  if (manifest.contains("images")) describe_image_folders(d, dir, manifest["shard"].value("begin", uint64_t{0}));
  add_file(d, "manifest.json", json());
  return d;
}

// YAML scalars and flow collections written as JSON, which YAML 1.2 reads as the same.
std::string yaml(const json& v) { return v.dump(); }

std::string card_text(const json& m, const Description& d) {
  const json& s = m["spec"];
  const uint64_t count = m.value("count", uint64_t{0}), pos = m["classes"].value("positive", uint64_t{0}),
                 neg = m["classes"].value("negative", uint64_t{0});
  char share[32];
  std::snprintf(share, sizeof share, "%.6f", count ? double(pos) / double(count) : 0.0);
  json model{{"name", s.value("model", "thesis")}, {"parameters", model_parameters(s)}};
  std::string y = "---\n";
  y += "name: " + yaml(data_set_name(m)) + "\n";
  y += "version: " + yaml(m.value("portalsim", "")) + "\n";
  y += "license: unknown\n";
  y += "command: " + yaml(regenerate_command(m)) + "\n";
  y += "spec: " + yaml(s) + "\n";
  y += "seed: " + yaml(s.value("seed", "0")) + "\n";
  y += "catalogue: " + yaml(m["catalogue"]) + "\n";
  y += "shard: " + yaml(m["shard"]) + "\n";
  y += "count: " + std::to_string(count) + "\n";
  y += "counts: " + yaml(json{{"positive", pos}, {"negative", neg}}) + "\n";
  y += std::string("class_balance: ") + share + "\n";
  y += "sensor_model: " + yaml(model) + "\n";
  y += "files:\n";
  for (const json& f : d.files) y += "  - " + yaml(f) + "\n";
  y += "  - " + yaml(json{{"name", "README.md"}, {"holds", file_meaning("README.md", d.portal)}}) + "\n";
  y += "  - " + yaml(json{{"name", "croissant.json"}, {"holds", file_meaning("croissant.json", d.portal)}}) + "\n";
  y += "---\n\n";
  y += "# " + data_set_name(m) + "\n\n";
  const Portal& p = d.portal;
  y += "Simulated security-portal scenarios made by portalsim " + m.value("portalsim", "") +
       ": for each scenario a person carrying 0 or more objects walks through a portal with " +
       (p.thesis_cameras() ? std::string("a passive millimetre-wave camera (upper and lower body), an infrared camera")
                           : p.camera_views()) +
       " and a walk-through metal detector (" + std::to_string(p.zones) + " zones).\n\n";
  y += "- **Scenarios:** " + std::to_string(count) + " (" + std::to_string(pos) + " threats, " + std::to_string(neg) +
       " not), indices " + std::to_string(m["shard"].value("begin", uint64_t{0})) + " to " +
       std::to_string(m["shard"].value("end", uint64_t{0})) + " of seed " + s.value("seed", "0") + ".\n";
  y += "- **Label rule:** " +
       (s.value("rule", "").empty() ? std::string("none (every scenario is labelled no)")
                                    : "`" + s.value("rule", "") + "`") +
       ".\n";
  y += "- **Sensor model:** `" + s.value("model", "thesis") + "`, tier `" + s.value("tier", "standard") +
       "`; every parameter is in the front matter's `sensor_model`.\n";
  // A view's own camera (raw grid, NETD) is the physics model's; the thesis model reads neither.
  for (const Portal::View& v : p.views)
    if (!v.own_camera.empty() && s.value("model", "thesis") == "physics")
      y += "- **View " + v.name + "** has a camera of its own, over the run's parameters: " + v.own_camera + ".\n";
  y += "- **Make it again** (the same bytes; `--batch`, `--threads` and MPI ranks never change them):\n\n";
  y += "  ```sh\n  " + regenerate_command(m) + "\n  ```\n\n";
  y += "## Files\n\n| file | what it holds |\n| --- | --- |\n";
  for (const json& f : d.files)
    y += "| `" + f["name"].get<std::string>() + "` | " + f["holds"].get<std::string>() + " |\n";
  y += "\n`croissant.json` describes every file's records and fields for loaders that read MLCommons Croissant; "
       "`manifest.json` holds each file's size and XXH3-64.\n\n";
  y += "## Licence\n\nportalsim states no licence for what it generates: the person who made this data set chooses "
       "one before sharing it, and should replace `license: unknown` above.\n";
  return y;
}

json croissant_json(const json& m, const Description& d) {
  json c;
  c["@context"] = croissant_context();
  c["@type"] = "sc:Dataset";
  c["conformsTo"] = "http://mlcommons.org/croissant/1.0";
  c["name"] = data_set_name(m);
  c["description"] =
      "Simulated security-portal scenarios (passive MMW camera, IR camera, walk-through metal detector) made by "
      "portalsim; the command that makes them again: " +
      regenerate_command(m);
  c["version"] = m.value("portalsim", "");
  c["license"] = "unknown";
  c["citeAs"] =
      "J. Natarajan, Simulation of Sensor Responses of Advanced Security Systems, M.S. thesis, The University of "
      "Texas at Arlington, 2006 (the simulator portalsim re-creates)";
  c["keywords"] = json::array({"security portal", "millimetre wave", "infrared", "metal detector", "synthetic data"});
  c["isLiveDataset"] = false;
  c["distribution"] = d.distribution;
  c["recordSet"] = d.record_sets;
  return c;
}

}  // namespace

std::string regenerate_command(const json& m) {
  const json& s = m.at("spec");
  RunSpec defaults;
  defaults.tier = s.value("tier", defaults.tier);
  const json base = defaults.to_json();
  std::string cmd = "portalsim generate";
  const std::string source = m["catalogue"].value("source", kBuiltInCatalogue);
  if (source != kBuiltInCatalogue) cmd += " --catalogue " + shell_quote(source);
  for (const auto& [key, value] : s.items()) {
    if (key == "scenarios_count" || (base.contains(key) && base[key] == value)) continue;
    if (key == "png_level" && value == kDefaultPngLevel) continue;      // absent from `base`: it has no image folders
    if (key == "count" && !s.value("scenarios", "").empty()) continue;  // the list's length
    std::string flag = "--" + key;
    std::replace(flag.begin(), flag.end(), '_', '-');
    if (value.is_boolean() && !find_knob(key)) {  // --balance, --compress, --annotations
      if (value.get<bool>()) cmd += " " + flag;
      continue;
    }
    std::string text;
    if (key == "objects")
      text = std::to_string(value[0].get<int>()) + ".." + std::to_string(value[1].get<int>());
    else if (value.is_array())
      for (const json& v : value) text += (text.empty() ? "" : ",") + knob_text(v);
    else
      text = knob_text(value);
    cmd += " " + flag + " " + shell_quote(text);
  }
  const json& shard = m["shard"];
  if (shard.value("count", 1) > 1)
    cmd += " --shard " + std::to_string(shard.value("index", 0)) + "/" + std::to_string(shard.value("count", 1));
  return cmd + " --out DIR";
}

void write_dataset_card(const std::string& dir, const json& manifest) {
  const Description d = describe(fs::path(dir), manifest);
  write_text_atomic((fs::path(dir) / "croissant.json").string(), croissant_json(manifest, d).dump(2) + "\n");
  write_text_atomic((fs::path(dir) / "README.md").string(), card_text(manifest, d));
}

}  // namespace portalsim
