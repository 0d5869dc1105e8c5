// `portalsim serve`: the thesis's GUI (appendix D.1-D.2) as a local web page. One
// catalogue, its assets and one backend, shared by every request; the page and its
// script are embedded in the binary.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "assets/assets.h"
#include "backend/backend.h"
#include "scene/catalogue.h"

namespace portalsim {

struct ServeOptions {
  std::string bind = "127.0.0.1";
  int port = 8080;  // 0 = any free port
  std::string root = ".";
  std::string self;                  // this binary, started for "Generate"
  std::vector<std::string> session;  // --catalogue/--assets/--backend to pass on to generate
  size_t max_body = 64 * 1024;       // request bodies over this get HTTP 413
};

class Server {
 public:
  // Checks --root and --bind; throws InputError.
  Server(const Catalogue& cat, const AssetSet& assets, Backend& backend, const ServeOptions& opt);
  ~Server();
  // Binds the socket; returns the port (useful with port 0). Throws OutputError.
  int bind();
  // Serves until stop() (blocking).
  void listen();
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace portalsim
