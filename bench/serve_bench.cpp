// portalsim serve's per-update latency: one POST /api/render over loopback, as the page
// sends on every change (backend run, PNG encoding, base64, JSON), warm. Each iteration
// moves the gun and changes the seed so that every answer is a real redraw. Reports the
// median and 95th percentile in ms; the target is < 100 ms.
#include <benchmark/benchmark.h>
#include <httplib.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <thread>

#include "cli/common.h"
#include "serve/server.h"

namespace portalsim {
namespace {

void BM_Serve_update(benchmark::State& state) {
  cli::CommonOptions common;
  cli::Session session = cli::open_session(common);
  ServeOptions opt;
  opt.port = 0;
  opt.root = std::filesystem::temp_directory_path().string();
  Server server(session.catalogue, session.assets, *session.backend, opt);
  const int port = server.bind();
  std::thread listener([&] { server.listen(); });
  httplib::Client client("127.0.0.1", port);
  client.set_read_timeout(60, 0);
  auto body = [](int i) {
    std::string objects;
    for (int r = 0; r < 13; ++r) objects += std::string(r ? "," : "") + (r == 3 + i % 3 ? "\"gun\"" : "\"none\"");
    return "{\"objects\":[" + objects + "],\"seed\":\"" + std::to_string(i) + "\"}";
  };
  for (int i = 0; i < 5; ++i) client.Post("/api/render", body(i), "application/json");  // warm
  std::vector<double> ms;
  int i = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    auto r = client.Post("/api/render", body(++i), "application/json");
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    if (!r || r->status != 200) {
      state.SkipWithError("render failed");
      break;
    }
  }
  server.stop();
  listener.join();
  if (ms.empty()) return;
  std::sort(ms.begin(), ms.end());
  state.counters["p50_ms"] = ms[ms.size() / 2];
  state.counters["p95_ms"] = ms[std::min(ms.size() - 1, ms.size() * 95 / 100)];
}
BENCHMARK(BM_Serve_update)->Iterations(200)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace portalsim
