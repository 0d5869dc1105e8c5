// portalsim catalogue: what a scenario can name, and the default images to look at.
#include <algorithm>
#include <cstdio>
#include <string>

#include "assets/image_io.h"
#include "cli/commands.h"
#include "cli/common.h"
#include "sink/staging.h"

namespace portalsim::cli {

namespace {
struct CatalogueOptions {
  CommonOptions common;
  std::string images;  // folder to write every resolved image into
};

int list(CatalogueOptions& o) {
  Session s;
  open_catalogue(s, o.common);
  const Catalogue& c = s.catalogue;
  std::printf("catalogue %s (hash %s)\n", c.source.c_str(), c.hash.c_str());
  std::printf("camera views:");
  for (const Sensor& v : c.sensors) {
    std::printf(" %s %s%s %dx%d", v.name.c_str(), camera_name(v.camera), v.side == Side::back ? " back" : "", v.width,
                v.height);
    // Its own camera's numbers, where they differ from the run's knobs.
    if (v.raw) std::printf(" raw %dx%d", (*v.raw)[0], (*v.raw)[1]);
    if (v.netd) std::printf(" netd %g K", *v.netd);
    std::printf(";");
  }
  std::printf(" alpha %.3g\n", c.images.alpha);
  std::printf("\nsubjects:\n");
  for (size_t i = 0; i < c.subjects.size(); ++i)  // what the body is drawn as: width and stature scales
    std::printf("  %zu  %s  build %g  height %g\n", i + 1, c.subjects[i].name.c_str(), c.subjects[i].shape.build,
                c.subjects[i].shape.height);
  std::printf("\nregions:\n");
  for (const Region& r : c.regions) {
    // The features' view whose rectangles hold it, named in the views line.
    const int view = first_feature_view(c.sensors, r.id - 1);
    std::printf("  %2d  %-15s %s\n", r.id, r.name.c_str(), view < 0 ? "" : c.sensors[view].name.c_str());
  }
  std::printf("\nobjects (name [variants] metal category, class, family, * in the default pool: aliases):\n");
  size_t width = 0;
  for (const Object& ob : c.objects) width = std::max(width, ob.name.size());
  std::vector<char> in_default(c.objects.size(), 0);
  for (int k : c.default_pool) in_default[k] = 1;
  for (size_t i = 0; i < c.objects.size(); ++i) {
    const Object& ob = c.objects[i];
    std::string vars, aliases;
    for (const Variant& v : ob.variants)
      if (!v.code.empty()) vars += (vars.empty() ? "" : ",") + v.code;
    for (const std::string& a : ob.aliases) aliases += (aliases.empty() ? "" : ", ") + a;
    // Left-aligned columns as printf's %-Ns gives them (never cut), then the aliases.
    const auto pad = [](std::string text, size_t n) {
      if (text.size() < n) text.resize(n, ' ');
      return text;
    };
    std::string shown = std::string("  ") + (in_default[i] ? '*' : ' ') + ' ' +
                        pad(ob.name, std::min<size_t>(width, 64)) + ' ' + pad(vars.empty() ? "" : "[" + vars + "]", 6) +
                        ' ' + pad(c.metal_categories[ob.metal], 7) + ' ' +
                        pad(ob.object_class.empty() ? "-" : ob.object_class, 7) + ' ' +
                        pad(ob.family.empty() ? "-" : ob.family, 8) + ' ' + aliases;
    shown.erase(shown.find_last_not_of(' ') + 1);  // no trailing blanks where there are no aliases
    std::printf("%s\n", shown.c_str());
  }
  if (!o.images.empty()) {
    StagedFolder folder(o.images);
    write_catalogue_images(s, folder);
    folder.commit();
    std::printf("\nimages written to %s\n", o.images.c_str());
  }
  return 0;
}

// A sprite set's file name: its camera, "_back" where mirrored, and its index where another
// set has the same camera and side at another scale.
std::string sprite_set_name(const Catalogue& c, size_t set) {
  const SpriteSet& a = c.sprite_sets[set];
  std::string name = std::string(camera_name(a.camera)) + (a.mirrored ? "_back" : "");
  for (size_t k = 0; k < c.sprite_sets.size(); ++k)
    if (k != set && c.sprite_sets[k].camera == a.camera && c.sprite_sets[k].mirrored == a.mirrored)
      return name + std::to_string(set + 1);
  return name;
}

}  // namespace

void write_catalogue_images(const Session& s, StagedFolder& folder) {
  const Catalogue& c = s.catalogue;
  for (size_t i = 0; i < s.assets.bases.size(); ++i)
    for (size_t k = 0; k < c.sensors.size(); ++k) {
      const Image& img = s.assets.bases[i][k];
      write_image(folder.path(subject_image_name(i, c.sensors[k])),
                  c.sensors[k].palette ? colourise(img, s.assets.palette) : img);
    }
  for (size_t v = 0; v < c.variant_list.size(); ++v) {
    std::string n = c.variant_name(static_cast<int>(v));
    for (char& ch : n)
      if (ch == ':') ch = '_';
    for (size_t set = 0; set < c.sprite_sets.size(); ++set)
      write_image(folder.path(n + "_" + sprite_set_name(c, set) + ".png"), s.assets.sprites[set][v]);
  }
  for (size_t k = 0; k < s.assets.noise.size(); ++k)
    write_image(folder.path("noise" + std::to_string(k + 1) + "_" + c.noise[k].name + ".png"), s.assets.noise[k]);
}

std::string subject_image_name(size_t subject, const Sensor& view) {
  return "subject" + std::to_string(subject + 1) + "_" + view.name + ".png";
}

std::function<int()> add_catalogue(CLI::App& app) {
  auto o = std::make_shared<CatalogueOptions>();
  CLI::App* sub = app.add_subcommand("catalogue", "list the subjects, regions and objects; optionally dump the images");
  sub->add_option("--catalogue", o->common.catalogue, "catalogue TOML file (default: the built-in one)");
  sub->add_option("--assets", o->common.assets, "folder in which the catalogue's image files are looked up first");
  sub->add_option("--images", o->images, "write every base image, sprite and noise pattern into this folder");
  return [o] { return list(*o); };
}

}  // namespace portalsim::cli
