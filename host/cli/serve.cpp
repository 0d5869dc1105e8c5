// portalsim serve: the thesis's GUI as a local web page (docs/guide/serve.md).
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <thread>

#include "cli/commands.h"
#include "cli/common.h"
#include "serve/server.h"

namespace portalsim::cli {

namespace {
struct ServeCmd {
  CommonOptions common;
  ServeOptions serve;
  BodyOptions body;
  CLI::App* app = nullptr;
};

int serve(ServeCmd& o) {
  // SIGINT/SIGTERM stop the server cleanly (its scratch folder is removed): every thread
  // (PoCL's too, so before the session opens) blocks them and one waits for them.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  const RunSpec bodies = bodies_spec(o.body);
  Session s;
  open_catalogue(s, o.common, &bodies);
  open_backend(s, o.common);
  char self[4096];
  const ssize_t n = ::readlink("/proc/self/exe", self, sizeof self - 1);
  o.serve.self = n > 0 ? std::string(self, static_cast<size_t>(n)) : std::string("portalsim");
  for (const char* flag : {"--catalogue", "--assets", "--backend", "--device"}) {
    CLI::Option* opt = o.app->get_option_no_throw(flag);
    if (opt && opt->count() > 0) o.serve.session.insert(o.serve.session.end(), {flag, opt->as<std::string>()});
  }
  // Its Generate draws the same bodies, whatever the page's seed.
  if (bodies.random_bodies())
    o.serve.session.insert(o.serve.session.end(),
                           {"--bodies", "random", "--body-count", std::to_string(bodies.random_bodies()), "--body-seed",
                            std::to_string(bodies.bodies_seed())});
  Server server(s.catalogue, s.assets, *s.backend, o.serve);
  const int port = server.bind();
  std::printf("portalsim serve: http://%s:%d/ (root %s)\n", o.serve.bind.c_str(), port, o.serve.root.c_str());
  std::fflush(stdout);
  std::thread waiter([&] {
    int sig = 0;
    sigwait(&stop_signals, &sig);
    server.stop();
  });
  server.listen();
  // listen() also returns when the socket fails; wake the waiter in that case.
  ::kill(::getpid(), SIGTERM);
  waiter.join();
  return 0;
}
}  // namespace

std::function<int()> add_serve(CLI::App& app) {
  auto o = std::make_shared<ServeCmd>();
  CLI::App* sub = app.add_subcommand("serve", "the thesis's GUI as a local web page: place objects, see the sensors");
  add_common_options(*sub, o->common);
  sub->add_option("--port", o->serve.port, "TCP port (default 8080; 0 = any free port)");
  sub->add_option("--bind", o->serve.bind, "address to listen on (default 127.0.0.1, loopback only)");
  sub->add_option("--root", o->serve.root, "folder that Save and Generate write under (default: current folder)");
  add_body_options(*sub, o->body);
  o->app = sub;
  return [o] { return serve(*o); };
}

}  // namespace portalsim::cli
