// portalsim serve at the HTTP level: the real binary on a free loopback port, driven by
// cpp-httplib's client. Bad inputs, names that try to leave --root, oversized requests,
// Save against simulate, and 8 clients x 200 requests at once.
#include <gtest/gtest.h>
#include <httplib.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "run_binary.h"
#include "support.h"

namespace fs = std::filesystem;
using json = nlohmann::json;
using portalsim::test::describe;
using portalsim::test::slurp;

namespace {

const std::vector<std::string> kGun{"none", "none", "none", "gun"};

// One server per test, rooted in a fresh folder: tmp/root is --root, tmp/cap the captured output.
class Serve : public ::testing::Test {
 protected:
  void SetUp() override {
    tmp_ = portalsim::test::make_temp_dir("portalsim-serve-test");
    fs::create_directories(tmp_ / "root");
    fs::create_directories(tmp_ / "cap");
    std::vector<std::string> args{"serve", "--port", "0", "--root", (tmp_ / "root").string()};
    for (const std::string& a : extra_args()) args.push_back(a);
    server_ = portalsim::test::start(tmp_ / "cap", args);
    // The URL line says the server is listening.
    portalsim::test::wait_until(
        [&] {
          const std::string out = slurp(server_.out_path);
          const size_t at = out.find("http://127.0.0.1:");
          if (at != std::string::npos && out.find('/', at + 17) != std::string::npos)
            port_ = std::stoi(out.substr(at + 17));
          return port_ != 0 || portalsim::test::has_ended(server_);
        },
        60);
    ASSERT_GT(port_, 0) << "no URL printed: " << slurp(server_.err_path);
  }
  void TearDown() override {
    if (server_.pid > 0) {
      ::kill(server_.pid, SIGTERM);
      const auto r = portalsim::test::finish(server_, 30);
      EXPECT_FALSE(r.timed_out);
      EXPECT_EQ(r.status, 0) << "SIGTERM stops the server cleanly\n" << describe(r);
    }
    std::error_code ec;
    fs::remove_all(tmp_, ec);
  }
  // More of serve's arguments (a fixture's own catalogue); tmp_ exists when this is called.
  virtual std::vector<std::string> extra_args() { return {}; }
  httplib::Client client() const {
    httplib::Client c("127.0.0.1", port_);
    c.set_read_timeout(60 * portalsim::test::kTimeScale, 0);
    return c;
  }
  httplib::Result post(const std::string& path, const json& body) const {
    return client().Post(path.c_str(), body.dump(), "application/json");
  }
  std::string error_of(const httplib::Result& r) const { return json::parse(r->body).value("error", ""); }
  // The generate job's state (GET /api/generate) once it is no longer running, up to 120 s.
  json finished_generate() const {
    json s;
    portalsim::test::wait_until(
        [&] {
          auto g = client().Get("/api/generate");
          s = g ? json::parse(g->body) : json();
          return s.value("state", "") != "running";
        },
        120, 50);
    return s;
  }
  fs::path root() const { return tmp_ / "root"; }

  fs::path tmp_;
  portalsim::test::Running server_;
  int port_ = 0;
};

TEST_F(Serve, PageAndCatalogueAreServed) {
  auto page = client().Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("<script src=\"/app.js\">"), std::string::npos);
  auto cat = client().Get("/api/catalogue");
  ASSERT_TRUE(cat);
  const json j = json::parse(cat->body);
  EXPECT_EQ(j["regions"].size(), 13u);
  EXPECT_NE(std::find(j["objects"].begin(), j["objects"].end(), "gun:v"), j["objects"].end());
  // The zones, each with the panel it transmits from (the page's two columns of bars).
  ASSERT_EQ(j["zones"].size(), 19u);
  std::string panels;
  for (const json& z : j["zones"]) panels += z["panel"].get<std::string>();
  EXPECT_EQ(panels, "aaaaaaaaabbbbbbbbbb");
  EXPECT_EQ(j["zones"][18]["id"], 19);
}

// The default catalogue with its first subject at 0.85 of the height: the page's hit boxes
// (/api/catalogue's per-subject places) move down with that subject's body.
class ServeShortSubject : public Serve {
 protected:
  std::vector<std::string> extra_args() override {
    const fs::path file = tmp_ / "short.toml";
    std::ofstream(file) << portalsim::test::with_subject_line(
        slurp(fs::path(PORTALSIM_SOURCE_DIR) / "scenarios" / "catalogue.toml"), 0, "height = 0.85");
    return {"--catalogue", file.string(), "--assets", (fs::path(PORTALSIM_SOURCE_DIR) / "scenarios").string()};
  }
};

TEST_F(ServeShortSubject, HitBoxesFollowTheSubjectsHeight) {
  auto cat = client().Get("/api/catalogue");
  ASSERT_TRUE(cat);
  ASSERT_EQ(cat->status, 200) << cat->body;
  const json j = json::parse(cat->body);
  ASSERT_EQ(j["regions"].size(), 13u);
  for (const json& r : j["regions"]) {
    ASSERT_EQ(r["places"].size(), j["subjects"].size()) << r.dump();
    const auto rect = r["rect"].get<std::vector<int>>(), shorter = r["places"][0].get<std::vector<int>>();
    EXPECT_EQ(r["places"][1].get<std::vector<int>>(), rect) << "subject 2 is of height 1: " << r.dump();
    EXPECT_GT(shorter[1], rect[1]) << "a shorter body holds its objects lower: " << r.dump();
    EXPECT_EQ(shorter[0], rect[0]);
    EXPECT_EQ(shorter[2], rect[2]);
    EXPECT_EQ(shorter[3], rect[3]);
  }
}

// serve --bodies random: the page lists the drawn bodies with their draw, renders any of
// them, and its Generate draws the same bodies (the body seed passed on).
class ServeRandomBodies : public Serve {
 protected:
  std::vector<std::string> extra_args() override {
    return {"--bodies", "random", "--body-count", "6", "--body-seed", "3", "--seed", "99"};
  }
};

TEST_F(ServeRandomBodies, ListsRendersAndGeneratesTheDrawnBodies) {
  auto cat = client().Get("/api/catalogue");
  ASSERT_TRUE(cat);
  const json j = json::parse(cat->body);
  ASSERT_EQ(j["subjects"].size(), 6u);
  EXPECT_EQ(j["subjects"][5], "body-006");
  ASSERT_EQ(j["subject_notes"].size(), 6u);
  EXPECT_NE(j["subject_notes"][0].get<std::string>().find(" m, arms-"), std::string::npos) << j["subject_notes"];
  for (const json& r : j["regions"]) EXPECT_EQ(r["places"].size(), 6u);
  auto r1 = post("/api/render", {{"objects", kGun}, {"subject", 1}}),
       r6 = post("/api/render", {{"objects", kGun}, {"subject", 6}});
  ASSERT_TRUE(r1 && r6);
  ASSERT_EQ(r6->status, 200) << r6->body;
  EXPECT_NE(json::parse(r1->body)["upper"], json::parse(r6->body)["upper"]) << "two bodies, two images";
  auto g = post("/api/generate", {{"objects", kGun}, {"subject", 6}, {"name", "bodies"}, {"count", 20}});
  ASSERT_TRUE(g);
  ASSERT_EQ(g->status, 200) << g->body;
  const json s = finished_generate();
  ASSERT_EQ(s["state"], "done") << s.dump();
  const std::string list = slurp(root() / "bodies" / "scenarios.csv");
  EXPECT_NE(list.find(",stature_mm,"), std::string::npos) << "the run's bodies are the drawn ones";
  const json manifest = json::parse(slurp(root() / "bodies" / "manifest.json"));
  EXPECT_EQ(manifest["spec"]["body_seed"], "3") << "the server's bodies, not the page's seed's";
}

TEST_F(Serve, RenderGivesTheThesisGunExample) {
  auto r = post("/api/render", {{"objects", kGun}, {"rule", "gun"}});
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  const json j = json::parse(r->body);
  EXPECT_EQ(j["metal"].get<std::vector<int>>(),
            (std::vector<int>{193, 112, 75, 2, 1, 1, 96, 200, 200, 190, 196, 53, 53, 94, 64, 82, 53, 200, 200}));
  EXPECT_TRUE(j["threat"].get<bool>());
  EXPECT_EQ(j["upper"].get<std::string>().rfind("data:image/png;base64,iVBORw0KGgo", 0), 0u);
}

// The page's IR palette changes the IR image, not the MMW views.
TEST_F(Serve, PaletteChangesTheIrImageOnly) {
  std::map<std::string, json> got;
  for (const char* palette : {"ironbow", "gray"}) {
    auto r = post("/api/render", {{"objects", kGun}, {"palette", palette}});
    ASSERT_TRUE(r);
    ASSERT_EQ(r->status, 200) << r->body;
    got[palette] = json::parse(r->body);
  }
  EXPECT_EQ(got["ironbow"]["upper"], got["gray"]["upper"]);
  EXPECT_NE(got["ironbow"]["ir"], got["gray"]["ir"]);
}

// Each bad input gets HTTP 400 and the message simulate prints for the same input.
TEST_F(Serve, BadInputsGet400WithTheCommandLinesMessage) {
  struct Case {
    json body;
    std::vector<std::string> cli;
  };
  const std::vector<Case> cases{
      {{{"objects", {"none", "bazooka"}}}, {"none", "bazooka"}},
      {{{"objects", kGun}, {"subject", 9}}, {"none", "none", "none", "gun", "--subject", "9"}},
      {{{"objects", kGun}, {"rule", "gun&"}}, {"none", "none", "none", "gun", "--rule", "gun&"}},
      {{{"objects", kGun}, {"seed", "12x"}}, {"none", "none", "none", "gun", "--seed", "12x"}},
      {{{"objects", kGun}, {"tier", "turbo"}}, {"none", "none", "none", "gun", "--tier", "turbo"}},
      {{{"objects", kGun}, {"placement", "cubic"}}, {"none", "none", "none", "gun", "--placement", "cubic"}},
      {{{"objects", kGun}, {"palette", "jet"}}, {"none", "none", "none", "gun", "--palette", "jet"}},
      {{{"objects", kGun}, {"threat", "maybe"}}, {"none", "none", "none", "gun", "--threat", "maybe"}},
      {{{"objects", kGun}, {"rule", "gun"}, {"threat", "yes"}},
       {"none", "none", "none", "gun", "--rule", "gun", "--threat", "yes"}},
  };
  for (const Case& c : cases) {
    auto r = post("/api/render", c.body);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 400) << c.body.dump();
    std::vector<std::string> args{"simulate", "--out", (tmp_ / "sim-bad").string()};
    args.insert(args.end(), c.cli.begin(), c.cli.end());
    const auto sim = portalsim::test::finish(portalsim::test::start(tmp_ / "cap", args));
    ASSERT_NE(sim.status, 0) << describe(sim);
    const std::string msg = error_of(r);
    EXPECT_FALSE(msg.empty());
    EXPECT_NE(sim.err.find(msg), std::string::npos) << "server: " << msg << "\n" << describe(sim);
  }
  for (
      const std::string body :
      {"", "not json", "[1,2]", R"({"objects":"gun"})", R"({"subject":"one"})", R"({"subject":1.5})",
       R"({"subject":1e300})", R"({"subject":18446744073709551615})", R"({"seed":5})",
       R"({"objects":["none","none","none","none","none","none","none","none","none","none","none","none","none","gun"]})"}) {
    auto r = client().Post("/api/render", body, "application/json");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 400) << body;
    EXPECT_FALSE(error_of(r).empty()) << body;
  }
  // A rule nested deeper than the parser may recurse: refused, the server stays up.
  auto deep =
      post("/api/render", {{"objects", kGun}, {"rule", std::string(30000, '(') + "gun" + std::string(30000, ')')}});
  ASSERT_TRUE(deep);
  EXPECT_EQ(deep->status, 400);
  EXPECT_NE(error_of(deep).find("nested deeper than 64 levels"), std::string::npos) << deep->body;
  EXPECT_TRUE(fs::is_empty(root()));
}

TEST_F(Serve, NamesCannotLeaveRoot) {
  fs::create_directories(tmp_ / "outside");
  fs::create_directory_symlink(tmp_ / "outside", root() / "link");
  for (const std::string name : {"../escape", "..", "/tmp/escape", "a/b", "link", ".hidden", "", "a\\b", "x\n"}) {
    for (const char* path : {"/api/save", "/api/generate"}) {
      auto r = post(path, {{"objects", kGun}, {"name", name}, {"count", 10}});
      ASSERT_TRUE(r);
      EXPECT_EQ(r->status, 400) << path << " " << name << ": " << r->body;
      EXPECT_NE(error_of(r).find("name"), std::string::npos) << r->body;
    }
  }
  EXPECT_TRUE(fs::is_empty(tmp_ / "outside"));
  EXPECT_FALSE(fs::exists(tmp_ / "escape"));
  EXPECT_FALSE(fs::exists("/tmp/escape"));
  // Files: only regular files under root, never through a symlink or "..".
  portalsim::test::spit(tmp_ / "outside" / "secret.txt", "TOP-SECRET-CONTENT");
  for (const char* p : {"/files/link/secret.txt", "/files/../outside/secret.txt", "/files/%2e%2e/outside/secret.txt",
                        "/files//etc/passwd"}) {
    auto r = client().Get(p);
    ASSERT_TRUE(r);
    EXPECT_NE(r->status, 200) << p;
    EXPECT_EQ(r->body.find("TOP-SECRET-CONTENT"), std::string::npos) << p;
  }
  // scenarios.csv as a symlink out of root is refused too.
  fs::create_symlink(tmp_ / "outside" / "list.csv", root() / "scenarios.csv");
  auto r = post("/api/save", {{"objects", kGun}, {"name", "ok"}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 400) << r->body;
  EXPECT_FALSE(fs::exists(tmp_ / "outside" / "list.csv"));
}

TEST_F(Serve, OversizedRequestsAreRefused) {
  json body{{"objects", kGun}, {"rule", std::string(200 * 1024, 'g')}};
  auto r = post("/api/render", body);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 413);
  auto ok = post("/api/render", {{"objects", kGun}});
  ASSERT_TRUE(ok);
  EXPECT_EQ(ok->status, 200);
}

// Save writes simulate's folder byte for byte and a scenarios.csv that generate accepts.
TEST_F(Serve, SaveEqualsSimulateAndFeedsGenerate) {
  for (const char* name : {"gun4", "gun4b"}) {
    auto r = post("/api/save", {{"objects", kGun}, {"rule", "gun"}, {"name", name}});
    ASSERT_TRUE(r);
    ASSERT_EQ(r->status, 200) << r->body;
  }
  auto again = post("/api/save", {{"objects", kGun}, {"name", "gun4"}});
  ASSERT_TRUE(again);
  EXPECT_EQ(again->status, 400) << "an existing folder must not be overwritten";
  const auto sim = portalsim::test::finish(portalsim::test::start(
      tmp_ / "cap", {"simulate", "none", "none", "none", "gun", "--rule", "gun", "--out", (tmp_ / "sim").string()}));
  ASSERT_EQ(sim.status, 0) << describe(sim);
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(tmp_ / "sim")) names.push_back(e.path().filename().string());
  std::vector<std::string> saved;
  for (const auto& e : fs::directory_iterator(root() / "gun4")) saved.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  std::sort(saved.begin(), saved.end());
  EXPECT_EQ(names, saved);
  for (const std::string& n : names) EXPECT_EQ(slurp(tmp_ / "sim" / n), slurp(root() / "gun4" / n)) << n;

  const auto gen = portalsim::test::finish(
      portalsim::test::start(tmp_ / "cap", {"generate", "--scenarios", (root() / "scenarios.csv").string(), "--out",
                                            (tmp_ / "gen").string(), "--what", "both", "--quiet"}));
  ASSERT_EQ(gen.status, 0) << describe(gen);
  EXPECT_NE(gen.out.find("2 scenarios"), std::string::npos) << gen.out;
  EXPECT_NE(gen.out.find("positive 2"), std::string::npos) << gen.out;
}

TEST_F(Serve, GenerateRunsAndLinksItsResults) {
  auto r = post("/api/generate", {{"objects", kGun}, {"rule", "gun"}, {"name", "ds"}, {"count", 200}});
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  const json s = finished_generate();
  ASSERT_EQ(s["state"], "done") << s.dump();
  EXPECT_EQ(s["done"], 200);
  auto manifest = client().Get("/files/ds/manifest.json");
  ASSERT_TRUE(manifest);
  EXPECT_EQ(manifest->status, 200);
  EXPECT_EQ(manifest->body, slurp(root() / "ds" / "manifest.json"));
  for (const char* count : {"0", "1000001", "-99999999999999999999", "1e300", "\"10\""}) {
    const std::string body =
        R"({"objects":["none","none","none","gun"],"name":"ds2","count":)" + std::string(count) + "}";
    auto bad = client().Post("/api/generate", body, "application/json");
    ASSERT_TRUE(bad);
    EXPECT_EQ(bad->status, 400) << body;
    EXPECT_NE(error_of(bad).find("count"), std::string::npos) << bad->body;
  }
  EXPECT_FALSE(fs::exists(root() / "ds2"));
}

long rss_kib(pid_t pid, const char* field) {
  const std::string status = slurp("/proc/" + std::to_string(pid) + "/status");
  const size_t at = status.find(field);
  return at == std::string::npos ? -1 : std::stol(status.substr(at + std::strlen(field) + 1));
}

// 8 clients x 200 requests at once: every answer is the right one, the server stays up
// and its memory stays bounded (the second half adds no more than a few MiB).
TEST_F(Serve, EightClientsTwoHundredRequestsEach) {
  std::atomic<int> wrong{0}, done{0};
  long rss_half = 0;
  auto wave = [&](int requests) {
    std::vector<std::thread> clients;
    for (int c = 0; c < 8; ++c)
      clients.emplace_back([&, c] {
        httplib::Client cl = client();
        for (int i = 0; i < requests; ++i) {
          const int kind = (c + i) % 4;
          const int want = kind < 2 ? 200 : 400;
          auto r = [&] {
            if (kind == 0)
              return cl.Post("/api/render",
                             json{{"objects", {"none", "none", "none", "gun"}}, {"seed", std::to_string(i)}}.dump(),
                             "application/json");
            if (kind == 1) return cl.Get("/api/catalogue");
            if (kind == 2) return cl.Post("/api/render", R"({"objects":["bazooka"]})", "application/json");
            return cl.Get("/files/../../etc/passwd");
          }();
          if (!r || r->status != want) ++wrong;
          ++done;
        }
      });
    for (auto& t : clients) t.join();
  };
  wave(100);
  rss_half = rss_kib(server_.pid, "VmRSS:");
  wave(100);
  const long rss_end = rss_kib(server_.pid, "VmRSS:"), peak = rss_kib(server_.pid, "VmHWM:");
  std::printf("serve load: %d requests, %d wrong answers, RSS after half %ld KiB, at end %ld KiB, peak %ld KiB\n",
              done.load(), wrong.load(), rss_half, rss_end, peak);
  EXPECT_EQ(done, 1600);
  EXPECT_EQ(wrong, 0);
  EXPECT_GT(peak, 0);
  EXPECT_LT(rss_end - rss_half, 64 * 1024) << "memory grows with the number of requests";
  auto r = post("/api/render", {{"objects", kGun}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
}

}  // namespace
