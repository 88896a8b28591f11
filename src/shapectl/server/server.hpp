#pragma once
// HTTP + WebSocket front of a Session (Boost.Beast): serves the page and its assets from a web
// root, upgrades /ws to the session protocol (protocol.hpp, docs/gui.md) and streams the state to
// every connected page at `state_rate` Hz. One network thread; the optimizer has its own.
#include <filesystem>
#include <memory>
#include <string>

#include <shapectl/server/session.hpp>

namespace shapectl::server {

struct ServerOptions {
  std::string host = "127.0.0.1";  // loopback unless told otherwise
  unsigned short port = 8080;      // 0: any free port (see Server::port())
  std::filesystem::path web_root;  // index.html and node_modules/ live here
  double state_rate = 30;          // Hz, state messages to each page
  int max_clients = 32;            // further WebSocket upgrades get 503
  // Concurrent HTTP connections, lowered to fit the open-file limit (RLIMIT_NOFILE). At the cap
  // a new connection closes the oldest one still waiting for its request, else it gets a 503.
  int max_http_connections = 256;
};

class Server {
 public:
  // Binds and listens; an InputError when the address is bad or the port taken.
  Server(Session& session, ServerOptions options);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  unsigned short port() const;  // the bound port
  std::string url() const;      // "http://127.0.0.1:8080/"
  // Serves until stop() or SIGINT/SIGTERM.
  void run();
  void stop();  // safe from any thread

  struct Impl;  // defined in server.cpp (public only so its helper classes can name it)

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace shapectl::server
