#include "serve/server.h"

#include <fcntl.h>
#include <httplib.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "base/embedded.h"
#include "base/error.h"
#include "base/sizes.h"
#include "io/input_file.h"
#include "plan/knobs.h"
#include "scene/bodies.h"
#include "serve/knob_fields.h"
#include "serve/one_scenario.h"
#include "serve/request.h"
#include "sink/staging.h"

extern char** environ;

namespace portalsim {
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

// A file the page may open through /api: larger ones are opened from disk.
constexpr uintmax_t kMaxServedFileBytes = 64 * kMiB;

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string base64(const std::string& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const unsigned v = (uint8_t)in[i] << 16 | (uint8_t)in[i + 1] << 8 | (uint8_t)in[i + 2];
    for (int k = 18; k >= 0; k -= 6) out += t[(v >> k) & 63];
  }
  if (i < in.size()) {
    const unsigned v = (uint8_t)in[i] << 16 | (i + 1 < in.size() ? (uint8_t)in[i + 1] << 8 : 0);
    out += t[(v >> 18) & 63];
    out += t[(v >> 12) & 63];
    out += i + 1 < in.size() ? t[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

struct Job {
  pid_t pid = -1;
  std::string name, out_dir, log;
  uint64_t count = 0;
  std::atomic<bool> running{false};
  int status = -1;
};

}  // namespace

struct Server::Impl {
  const Catalogue& cat;
  const AssetSet& assets;
  Backend& backend;
  ServeOptions opt;
  fs::path root, scratch;
  httplib::Server http;
  std::mutex backend_mutex, csv_mutex, job_mutex;
  std::atomic<uint64_t> counter{0};
  std::shared_ptr<Job> job;
  std::thread job_waiter;

  Impl(const Catalogue& c, const AssetSet& a, Backend& b, const ServeOptions& o)
      : cat(c), assets(a), backend(b), opt(o) {
    std::error_code ec;
    if (!fs::is_directory(opt.root, ec)) throw InputError("--root: " + opt.root + " is not a folder");
    root = fs::canonical(opt.root, ec);
    if (ec) throw InputError("--root: " + opt.root + ": " + ec.message());
    if (opt.port < 0 || opt.port > 65535)
      throw InputError("--port: " + std::to_string(opt.port) + " is not 0 to 65535");
    std::string tmpl = (fs::temp_directory_path() / "portalsim-serve-XXXXXX").string();
    if (!::mkdtemp(tmpl.data())) throw OutputError(tmpl + ": cannot create a scratch folder: " + std::strerror(errno));
    scratch = tmpl;
    routes();
  }
  ~Impl() {
    // A running generate is interrupted the way generate documents: it checkpoints and
    // can be continued with --resume.
    if (job && job->running) ::kill(job->pid, SIGTERM);
    if (job_waiter.joinable()) job_waiter.join();
    std::error_code ec;
    fs::remove_all(scratch, ec);
  }

  // Runs the scenario into `dir` (all or nothing); returns the metal zones.
  std::vector<int> run(const Request& r, const Scenario& scene, const std::string& dir) {
    BatchOutput out;
    std::lock_guard<std::mutex> lock(backend_mutex);
    write_one_scenario(dir, cat, backend, scene, r.plan, procedural::ir_palette(r.plan.palette), FolderOptions{}, out);
    return std::vector<int>(out.metal_of(0), out.metal_of(0) + cat.zones);
  }

  json render(const std::string& body) {
    const Request r = parse_request(cat, body);
    const Scenario& scene = r.scene;
    const fs::path dir = scratch / ("r" + std::to_string(counter++));
    json res;
    try {
      res["metal"] = run(r, scene, dir.string());
      res["threat"] = scene.label == 1;
      for (const Sensor& s : cat.sensors)
        res[s.name] = "data:image/png;base64," + base64(read_file(dir / (s.name + ".png")));
    } catch (...) {
      std::error_code ec;
      fs::remove_all(dir, ec);
      throw;
    }
    std::error_code ec;
    fs::remove_all(dir, ec);
    return res;
  }

  // Refuses a name whose folder under root is a symlink or exists already.
  fs::path new_folder(const std::string& name) const {
    const fs::path p = root / check_name(name, "name");
    std::error_code ec;
    const fs::file_status st = fs::symlink_status(p, ec);
    if (fs::is_symlink(st)) throw InputError("name: \"" + name + "\" is a symbolic link under --root; refused");
    if (fs::exists(st)) throw InputError("name: \"" + name + "\" exists already under --root");
    return p;
  }

  json save(const std::string& body) {
    const Request r = parse_request(cat, body);
    const Scenario& scene = r.scene;
    // One save at a time: the name check, the folder and the list row go together.
    std::lock_guard<std::mutex> lock(csv_mutex);
    const fs::path dir = new_folder(r.name);
    const fs::path csv = root / "scenarios.csv";
    {
      std::error_code ec;
      if (fs::is_symlink(fs::symlink_status(csv, ec)))
        throw InputError("scenarios.csv under --root is a symbolic link; refused");
    }
    json res;
    res["metal"] = run(r, scene, dir.string());
    std::string line = std::to_string(scene.subject + 1);
    for (int i = 0; i < cat.region_count(); ++i)
      line.append(",").append(scene.objects[i] == kNoObject ? std::string("none") : cat.variant_name(scene.objects[i]));
    line += scene.label == 1 ? ",yes\n" : ",no\n";
    std::string text = fs::exists(csv) ? read_file(csv) : std::string();
    if (text.empty()) {
      text = "subject";
      for (int i = 1; i <= cat.region_count(); ++i) text += ",region" + std::to_string(i);
      text += ",label\n";
    }
    write_text_atomic(csv.string(), text + line);
    res["folder"] = dir.filename().string();
    res["scenarios_csv"] = "scenarios.csv";
    res["threat"] = scene.label == 1;
    return res;
  }

  json generate(const std::string& body) {
    const Request r = parse_request(cat, body);
    const Scenario& scene = r.scene;
    const int64_t count = r.count;
    if (count < 1 || count > 1000000) throw InputError("--count: " + std::to_string(count) + " is not 1 to 1000000");
    std::string pool;
    int placed = 0;
    for (int16_t v : scene.objects)
      if (v != kNoObject) {
        const std::string name = cat.object_of(v).name;
        if (pool.find("," + name + ",") == std::string::npos && pool.rfind(name + ",", 0) != 0) pool += name + ",";
        ++placed;
      }
    if (placed == 0) throw InputError("generate: place at least one object; its objects make the pool");
    pool.pop_back();
    std::lock_guard<std::mutex> lock(job_mutex);
    if (job && job->running) throw InputError("generate: a run is already going (" + job->name + ")");
    const fs::path dir = new_folder(r.name);
    std::vector<std::string> args{opt.self,
                                  "generate",
                                  "--quiet",
                                  "--count",
                                  std::to_string(count),
                                  "--seed",
                                  r.seed,
                                  "--out",
                                  dir.string(),
                                  "--pool",
                                  pool,
                                  "--objects",
                                  "0.." + std::to_string(placed),
                                  "--subjects",
                                  std::to_string(r.in.subject),
                                  "--tier",
                                  r.tier,
                                  "--what",
                                  "both",
                                  "--batch",
                                  "64"};
    // The page's model, knob by knob; a fidelity knob only where it overrides the tier.
    Plan tier;
    tier.fidelity = tier_fidelity(parse_tier(r.tier, "--tier"));
    for (const Knob& k : knobs())
      if (!k.fidelity || k.get(r.plan) != k.get(tier)) args.insert(args.end(), {k.flag(), knob_text(k.get(r.plan))});
    if (!r.in.rule.empty()) args.insert(args.end(), {"--rule", r.in.rule});
    args.insert(args.end(), opt.session.begin(), opt.session.end());
    if (job_waiter.joinable()) job_waiter.join();
    auto jb = std::make_shared<Job>();
    jb->name = dir.filename().string();
    jb->out_dir = dir.string();
    jb->count = static_cast<uint64_t>(count);
    jb->log = (scratch / ("generate" + std::to_string(counter++) + ".log")).string();
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 1, jb->log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
    // The child gets default signal handling back (serve blocks SIGINT/SIGTERM in its threads).
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    sigset_t none;
    sigemptyset(&none);
    posix_spawnattr_setsigmask(&attr, &none);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK);
    const int rc = posix_spawn(&jb->pid, argv[0], &fa, &attr, argv.data(), environ);
    posix_spawnattr_destroy(&attr);
    posix_spawn_file_actions_destroy(&fa);
    if (rc != 0) throw OutputError("generate: cannot start " + opt.self + ": " + std::strerror(rc));
    jb->running = true;
    job = jb;
    job_waiter = std::thread([jb] {
      int ws = 0;
      while (::waitpid(jb->pid, &ws, 0) < 0 && errno == EINTR) {
      }
      jb->status = WIFEXITED(ws) ? WEXITSTATUS(ws) : 128 + WTERMSIG(ws);
      jb->running = false;
    });
    return json{{"name", jb->name}, {"count", jb->count}};
  }

  json job_status() {
    std::lock_guard<std::mutex> lock(job_mutex);
    if (!job) return json{{"state", "none"}};
    json res{{"name", job->name}, {"count", job->count}};
    // Progress: rows of the scenario list written so far (header excluded).
    uint64_t rows = 0;
    for (const char* f : {"scenarios.csv.partial", "scenarios.csv"}) {
      const std::string text = read_file(fs::path(job->out_dir) / f);
      if (!text.empty()) rows = std::count(text.begin(), text.end(), '\n') - 1;
    }
    res["done"] = rows;
    if (job->running) {
      res["state"] = "running";
    } else if (job->status == 0) {
      res["state"] = "done";
      json files = json::array();
      std::error_code ec;
      for (const auto& e : fs::directory_iterator(job->out_dir, ec))
        if (e.is_regular_file()) files.push_back(e.path().filename().string());
      std::sort(files.begin(), files.end());
      res["files"] = files;
    } else {
      res["state"] = "failed";
      res["error"] = read_file(job->log);
    }
    return res;
  }

  // Files under root, for the links to a generate run's results. Every component is
  // checked and none may be a symlink.
  void file(const httplib::Request& req, httplib::Response& res) {
    const std::string rel = req.matches[1];
    fs::path p = root;
    size_t start = 0;
    while (start <= rel.size()) {
      const size_t slash = std::min(rel.find('/', start), rel.size());
      p /= check_name(rel.substr(start, slash - start), "file");
      std::error_code ec;
      if (fs::is_symlink(fs::symlink_status(p, ec))) throw InputError("file: \"" + rel + "\" passes a symbolic link");
      start = slash + 1;
    }
    std::error_code ec;
    if (!fs::is_regular_file(p, ec)) throw InputError("file: \"" + rel + "\" is not a file under --root");
    if (fs::file_size(p, ec) > kMaxServedFileBytes)
      throw InputError("file: \"" + rel + "\" is over " + std::to_string(kMaxServedFileBytes / kMiB) +
                       " MiB; open it from disk");
    const std::string ext = p.extension().string();
    const char* type = ext == ".png" ? "image/png" : ext == ".json" ? "application/json" : "text/plain";
    res.set_content(read_file(p), type);
  }

  using Handler = json (Impl::*)(const std::string&);
  void api(const httplib::Request& req, httplib::Response& res, Handler h) {
    try {
      res.set_content((this->*h)(req.body).dump(), "application/json");
    } catch (const InputError& e) {
      res.status = 400;
      res.set_content(json{{"error", e.what()}}.dump(), "application/json");
    } catch (const OutputError& e) {
      res.status = 500;
      res.set_content(json{{"error", e.what()}}.dump(), "application/json");
    }
  }

  void routes() {
    auto page = [](std::string_view text, const char* type) {
      return
          [text, type](const httplib::Request&, httplib::Response& res) { res.set_content(std::string(text), type); };
    };
    http.Get("/", page(embedded::serve_index_html, "text/html; charset=utf-8"));
    http.Get("/app.js", page(embedded::serve_app_js, "text/javascript"));
    http.Get("/style.css", page(embedded::serve_style_css, "text/css"));
    http.Get("/api/catalogue", [this](const httplib::Request&, httplib::Response& res) {
      res.set_content(catalogue().dump(), "application/json");
    });
    http.Get("/api/knobs", [](const httplib::Request&, httplib::Response& res) {
      res.set_content(knob_list().dump(), "application/json");
    });
    http.Post("/api/render", [this](const httplib::Request& q, httplib::Response& r) { api(q, r, &Impl::render); });
    http.Post("/api/save", [this](const httplib::Request& q, httplib::Response& r) { api(q, r, &Impl::save); });
    http.Post("/api/generate", [this](const httplib::Request& q, httplib::Response& r) { api(q, r, &Impl::generate); });
    http.Get("/api/generate", [this](const httplib::Request&, httplib::Response& r) {
      r.set_content(job_status().dump(), "application/json");
    });
    http.Get(R"(/files/(.+))", [this](const httplib::Request& q, httplib::Response& r) {
      try {
        file(q, r);
      } catch (const InputError& e) {
        r.status = 400;
        r.set_content(json{{"error", e.what()}}.dump(), "application/json");
      }
    });
    http.set_payload_max_length(opt.max_body);
    http.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
      std::string what = "internal error";
      try {
        std::rethrow_exception(ep);
      } catch (const std::exception& e) {
        what = e.what();
      } catch (...) {
      }
      res.status = 500;
      res.set_content(json{{"error", what}}.dump(), "application/json");
    });
  }

  json catalogue() const {
    const Catalogue& c = cat;
    json j;
    j["views"] = json::array();
    for (const Sensor& v : c.sensors)
      j["views"].push_back({{"name", v.name},
                            {"camera", camera_name(v.camera)},
                            {"side", side_name(v.side)},
                            {"size", {v.width, v.height}}});
    j["subjects"] = json::array();
    j["subject_notes"] = json::array();  // a random body's draw, for the page's list
    for (const Subject& sub : c.subjects) {
      j["subjects"].push_back(sub.name);
      j["subject_notes"].push_back(body_summary(sub));
    }
    j["regions"] = json::array();
    for (size_t k = 0; k < c.regions.size(); ++k) {
      const Region& r = c.regions[k];
      // The features' view whose rectangles hold the region (else its first view), named in
      // the views table.
      int s = first_feature_view(c.sensors, static_cast<int>(k));
      if (s < 0) s = first_view(c.sensors, static_cast<int>(k));
      const Sensor& view = c.sensors[static_cast<size_t>(s)];
      // Where the region holds an object on each subject: the rectangle moved with the
      // subject's stature (Sensor::place), which the page's hit boxes follow.
      json places = json::array();
      for (size_t sub = 0; sub < c.subjects.size(); ++sub) {
        const Rect p = view.place(static_cast<int>(sub), static_cast<int>(k));
        places.push_back({p.x, p.y, p.w, p.h});
      }
      const Rect& rc = view.rects[k];
      j["regions"].push_back({{"id", r.id},
                              {"name", r.name},
                              {"view", view.name},
                              {"size", {view.width, view.height}},
                              {"rect", {rc.x, rc.y, rc.w, rc.h}},
                              {"places", places}});
    }
    // The metal detector's zones and the panel each transmits from ([metal.physics]
    // tx_panel; null without it), which the page's two columns of bars follow.
    j["zones"] = json::array();
    for (int z = 0; z < c.zones; ++z) {
      json panel = nullptr;
      if (c.metal_physics.present) panel = c.metal_physics.tx_side[z] < 0 ? "a" : "b";
      j["zones"].push_back({{"id", z + 1}, {"panel", panel}});
    }
    j["objects"] = json::array();
    for (size_t v = 0; v < c.variant_list.size(); ++v) j["objects"].push_back(c.variant_name(static_cast<int>(v)));
    j["tiers"] = {"fast", "standard", "exact"};
    return j;
  }
};

Server::Server(const Catalogue& cat, const AssetSet& assets, Backend& backend, const ServeOptions& opt)
    : impl_(std::make_unique<Impl>(cat, assets, backend, opt)) {}
Server::~Server() = default;

int Server::bind() {
  const int port = impl_->opt.port == 0
                       ? impl_->http.bind_to_any_port(impl_->opt.bind)
                       : (impl_->http.bind_to_port(impl_->opt.bind, impl_->opt.port) ? impl_->opt.port : -1);
  if (port < 0)
    throw OutputError("--bind/--port: cannot listen on " + impl_->opt.bind + ":" + std::to_string(impl_->opt.port));
  return port;
}

void Server::listen() { impl_->http.listen_after_bind(); }
void Server::stop() { impl_->http.stop(); }

}  // namespace portalsim
