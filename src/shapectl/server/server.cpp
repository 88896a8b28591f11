#include <shapectl/server/server.hpp>

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <deque>
#include <iostream>
#include <list>
#include <set>
#include <utility>

#include <boost/asio.hpp>
#include <boost/beast.hpp>

#include <shapectl/io/input_error.hpp>
#include <shapectl/server/http_rules.hpp>
#include <shapectl/server/log_limiter.hpp>

namespace shapectl::server {

namespace {
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using Clock = std::chrono::steady_clock;

constexpr std::size_t max_queued_frames = 1024;  // a client this far behind is dropped
constexpr std::size_t max_queued_stream = 4;     // state/position frames dropped beyond this
constexpr int max_client_log_lines_per_second = 10;
constexpr int max_log_lines_per_second = 20;  // everything together
// A request must arrive complete this long after the connection opened or the previous
// response went out: half-sent requests and idle keep-alive connections are closed early.
constexpr auto request_timeout = std::chrono::seconds(5);
constexpr auto response_timeout = std::chrono::seconds(30);  // slow readers are dropped
// After a failed accept() (EMFILE: out of descriptors), accepting again at once would spin.
constexpr auto accept_pause = std::chrono::milliseconds(100);

class Client;
class HttpConnection;

// HTTP connections that fit the open-file limit: a reserve for the process itself and the
// WebSocket pages, then two descriptors per connection (its socket and the file it sends).
std::size_t http_connection_cap(int configured, int max_clients) {
  rlimit limit{};
  if (getrlimit(RLIMIT_NOFILE, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY)
    return static_cast<std::size_t>(configured);
  const long files = static_cast<long>(std::min<rlim_t>(limit.rlim_cur, 1 << 20));
  return static_cast<std::size_t>(std::clamp<long>((files - 64 - max_clients) / 2, 4, configured));
}

std::string_view view(beast::string_view s) { return {s.data(), s.size()}; }

bool out_of_descriptors(const beast::error_code& ec) {
  return ec == beast::errc::too_many_files_open || ec == beast::errc::too_many_files_open_in_system;
}
}  // namespace

struct Server::Impl : std::enable_shared_from_this<Server::Impl> {
  Impl(Session& s, ServerOptions o)
      : session(s),
        options(std::move(o)),
        http_cap(http_connection_cap(options.max_http_connections, options.max_clients)) {}
  Session& session;
  ServerOptions options;
  std::size_t http_cap;
  // Open HTTP connections, oldest first (each one adds and removes itself).
  std::list<HttpConnection*> http_connections;
  LogLimiter log_limit{max_log_lines_per_second, std::chrono::seconds(1)};
  LogLimiter accept_log_limit{1,
                              std::chrono::seconds(1)};  // a failing accept() says so once a second
  // Client objects alive, handshakes under way included; declared before ioc so it outlives the
  // handlers that ioc destroys.
  int websockets = 0;
  net::io_context ioc{1};
  tcp::acceptor acceptor{ioc};
  net::steady_timer accept_timer{ioc};
  net::steady_timer ticker{ioc};
  net::signal_set signals{ioc, SIGINT, SIGTERM};
  net::steady_timer goodbye_timer{ioc};
  Clock::time_point next_tick;
  std::set<std::shared_ptr<Client>> clients;  // after the handshake
  int next_client_id = 1;

  void accept();
  void admit(tcp::socket socket);
  bool evict_idle_http();
  void log(const std::string& line);
  void tick();
  void handle_message(const std::shared_ptr<Client>& client, std::string_view text);
  void broadcast_scene();
  // SIGINT/SIGTERM: every page gets a close frame ("going away"), then the loop stops.
  void close_all_and_stop();
};

namespace {

void log_line(const std::string& line) { std::cerr << "serve: " << line << std::endl; }

// One WebSocket peer: a read loop and a write queue on the network thread.
class Client : public std::enable_shared_from_this<Client> {
 public:
  Client(tcp::socket socket, Server::Impl& server, int id)
      : ws_(std::move(socket)), server_(server), id_(id) {
    ++server_.websockets;
  }
  ~Client() { --server_.websockets; }
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  int id() const { return id_; }
  std::shared_ptr<const ControllerSnapshot> positions_sent;

  void accept(http::request<http::string_body> request) {
    // Pings after 10 s of silence; a peer that vanished without closing is dropped after 20 s.
    websocket::stream_base::timeout timeouts{};
    timeouts.handshake_timeout = std::chrono::seconds(10);
    timeouts.idle_timeout = std::chrono::seconds(20);
    timeouts.keep_alive_pings = true;
    ws_.set_option(timeouts);
    ws_.read_message_max(max_message_bytes);
    ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return self->log("handshake failed: " + ec.message());
      self->server_.clients.insert(self);
      self->log("connected (" + std::to_string(self->server_.clients.size()) + " clients)");
      self->send(std::make_shared<const std::string>(self->server_.session.scene_message()), false);
      self->read();
    });
  }

  // `streamed` frames (state, positions) are dropped while the client is behind.
  void send(std::shared_ptr<const std::string> data, bool binary, bool streamed = false) {
    if (closed_) return;
    if (streamed && queue_.size() >= max_queued_stream) return;
    if (queue_.size() >= max_queued_frames) return close("not reading its messages");
    queue_.push_back({std::move(data), binary});
    if (queue_.size() == 1) write_next();
  }
  bool behind() const { return queue_.size() >= max_queued_stream; }

  // The server stops: a close frame says so (code 1001), then the connection ends. Bounded by
  // the server's goodbye time, after which the loop stops whatever the peer does.
  void go_away() {
    if (closed_) return;
    closed_ = true;
    server_.clients.erase(shared_from_this());
    if (queue_.size() > 1)
      queue_.erase(queue_.begin() + 1, queue_.end());  // the front is on its way
    ws_.async_close(websocket::close_reason(websocket::close_code::going_away, "server stopped"),
                    [self = shared_from_this()](beast::error_code) {});
  }

  // Per client first, so one noisy page does not use up the server's whole log budget.
  void log(const std::string& line) {
    const std::string prefix = "client " + std::to_string(id_) + ": ";
    int dropped = 0;
    const bool admitted = log_limit_.admit(Clock::now(), dropped);
    if (dropped > 0) server_.log(prefix + std::to_string(dropped) + " more lines suppressed");
    if (admitted) server_.log(prefix + line);
  }

 private:
  struct Frame {
    std::shared_ptr<const std::string> data;
    bool binary;
  };

  void read() {
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      self->on_read(ec);
    });
  }

  void on_read(beast::error_code ec) {
    if (ec) return close(ec == websocket::error::closed ? "closed" : ec.message());
    if (ws_.got_text()) {
      const std::string text = beast::buffers_to_string(buffer_.data());
      server_.handle_message(shared_from_this(), text);
    } else {
      log("bad message: binary frame");
      send(std::make_shared<const std::string>(
               error_reply(nullptr, "message: expected a JSON text message, got a binary one")),
           false);
    }
    buffer_.consume(buffer_.size());
    read();
  }

  void write_next() {
    ws_.binary(queue_.front().binary);
    ws_.async_write(net::buffer(*queue_.front().data),
                    [self = shared_from_this()](beast::error_code ec, std::size_t) {
                      if (ec) return self->close(ec.message());
                      self->queue_.pop_front();
                      if (!self->queue_.empty()) self->write_next();
                    });
  }

  void close(const std::string& why) {
    if (closed_) return;
    closed_ = true;
    log("disconnected: " + why);
    server_.clients.erase(shared_from_this());
    beast::error_code ignored;
    beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ignored);
    beast::get_lowest_layer(ws_).close();
  }

  websocket::stream<beast::tcp_stream> ws_;
  beast::flat_buffer buffer_;
  Server::Impl& server_;
  int id_;
  std::deque<Frame> queue_;
  bool closed_ = false;
  LogLimiter log_limit_{max_client_log_lines_per_second, std::chrono::seconds(1)};
};

// One HTTP connection: static files, or the upgrade to a Client on /ws.
class HttpConnection : public std::enable_shared_from_this<HttpConnection> {
 public:
  HttpConnection(tcp::socket socket, Server::Impl& server)
      : stream_(std::move(socket)), server_(server) {
    server_.http_connections.push_back(this);
    place_ = std::prev(server_.http_connections.end());
  }
  ~HttpConnection() { forget(); }
  HttpConnection(const HttpConnection&) = delete;
  HttpConnection& operator=(const HttpConnection&) = delete;

  void read() {
    parser_.emplace();
    parser_->header_limit(16 * 1024);
    parser_->body_limit(16 * 1024);
    waiting_ = true;
    stream_.expires_after(request_timeout);
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) {
                       self->waiting_ = false;
                       self->on_read(ec);
                     });
  }

  // Idle or in the middle of a request, rather than sending a response.
  bool waiting_for_request() const { return waiting_; }
  // Closes the socket now, freeing its descriptor; the pending read ends with an error.
  void evict() {
    forget();
    stream_.close();
  }

 private:
  // No longer counted among the server's HTTP connections.
  void forget() {
    if (!listed_) return;
    server_.http_connections.erase(place_);
    listed_ = false;
  }

  void on_read(beast::error_code ec) {
    if (ec) return shutdown();
    http::request<http::string_body> request = parser_->release();
    const std::string host(request[http::field::host]);
    if (!host_allowed(host, server_.options.host))
      return reply_text(request, http::status::forbidden, "host not allowed\n");
    if (websocket::is_upgrade(request)) return upgrade(std::move(request), host);
    if (request.method() != http::verb::get && request.method() != http::verb::head)
      return reply_text(request, http::status::method_not_allowed, "GET or HEAD only\n");
    const std::string_view target = view(request.target());
    std::optional<std::filesystem::path> file;
    if (!target.starts_with(robot_mesh_prefix))
      file = resolve_static_file(server_.options.web_root, target);
    else if (const auto mesh = parse_robot_mesh_target(target))
      file = server_.session.robot_mesh_file(mesh->index, mesh->extension);
    if (!file) return reply_text(request, http::status::not_found, "not found\n");
    http::file_body::value_type body;
    body.open(file->c_str(), beast::file_mode::scan, ec);
    if (out_of_descriptors(ec) && server_.evict_idle_http())
      body.open(file->c_str(), beast::file_mode::scan, ec);
    if (out_of_descriptors(ec))
      return reply_text(request, http::status::service_unavailable, "busy, try again\n");
    if (ec) return reply_text(request, http::status::not_found, "not found\n");
    const auto size = body.size();
    if (request.method() == http::verb::head) {
      http::response<http::empty_body> response{http::status::ok, request.version()};
      decorate(response, request, content_type(*file));
      response.content_length(size);
      return send(std::move(response));
    }
    http::response<http::file_body> response{std::piecewise_construct,
                                             std::make_tuple(std::move(body)),
                                             std::make_tuple(http::status::ok, request.version())};
    decorate(response, request, content_type(*file));
    response.content_length(size);
    send(std::move(response));
  }

  void upgrade(http::request<http::string_body> request, const std::string& host) {
    if (request.target() != "/ws")
      return reply_text(request, http::status::not_found, "not found\n");
    if (!origin_allowed(view(request[http::field::origin]), host))
      return reply_text(request, http::status::forbidden, "origin not allowed\n");
    if (server_.websockets >= server_.options.max_clients)
      return reply_text(request, http::status::service_unavailable, "too many clients\n");
    stream_.expires_never();
    forget();  // a WebSocket page now, counted by max_clients
    auto client =
        std::make_shared<Client>(stream_.release_socket(), server_, server_.next_client_id++);
    client->accept(std::move(request));
  }

  template <class Response>
  void decorate(Response& response, const http::request<http::string_body>& request,
                const std::string& type) {
    response.set(http::field::server, "shapectl");
    response.set(http::field::content_type, type);
    response.set(http::field::cache_control, "no-cache");
    response.set("X-Content-Type-Options", "nosniff");
    response.set("X-Frame-Options", "DENY");
    response.keep_alive(request.keep_alive());
  }

  void reply_text(const http::request<http::string_body>& request, http::status status,
                  const std::string& text) {
    http::response<http::string_body> response{status, request.version()};
    decorate(response, request, "text/plain; charset=utf-8");
    response.body() = text;
    response.prepare_payload();
    send(std::move(response));
  }

  template <class Response>
  void send(Response&& response) {
    auto held = std::make_shared<std::decay_t<Response>>(std::forward<Response>(response));
    response_ = held;
    stream_.expires_after(response_timeout);
    http::async_write(stream_, *held,
                      [self = shared_from_this(), held](beast::error_code ec, std::size_t) {
                        self->response_.reset();
                        if (ec || !held->keep_alive()) return self->shutdown();
                        self->read();
                      });
  }

  void shutdown() {
    beast::error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
  }

  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  std::shared_ptr<void> response_;
  Server::Impl& server_;
  std::list<HttpConnection*>::iterator place_;
  bool listed_ = true;
  bool waiting_ = false;
};

// Beyond the cap with every connection busy: a short 503 without blocking, then close.
void refuse(tcp::socket socket) {
  static constexpr std::string_view busy =
      "HTTP/1.1 503 Service Unavailable\r\nContent-Type: text/plain\r\nContent-Length: 5\r\n"
      "Connection: close\r\n\r\nbusy\n";
  beast::error_code ignored;
  socket.non_blocking(true, ignored);
  socket.write_some(net::buffer(busy.data(), busy.size()), ignored);
  socket.shutdown(tcp::socket::shutdown_both, ignored);
  socket.close(ignored);
}

}  // namespace

void Server::Impl::accept() {
  acceptor.async_accept([self = shared_from_this()](beast::error_code ec, tcp::socket socket) {
    if (ec == net::error::operation_aborted) return;
    if (!ec) {
      self->admit(std::move(socket));
      return self->accept();
    }
    // Out of descriptors (EMFILE) or the like: free one by closing an idle connection and try
    // again; with nothing to close, pause instead of spinning.
    int dropped = 0;
    if (self->accept_log_limit.admit(Clock::now(), dropped))
      self->log("accept failed: " + ec.message() +
                (dropped > 0 ? " (" + std::to_string(dropped) + " times more)" : std::string()));
    if (self->evict_idle_http()) return self->accept();
    self->accept_timer.expires_after(accept_pause);
    self->accept_timer.async_wait([self](beast::error_code wait_ec) {
      if (!wait_ec) self->accept();
    });
  });
}

void Server::Impl::admit(tcp::socket socket) {
  if (http_connections.size() >= http_cap) {
    if (!evict_idle_http()) {
      log("HTTP connection limit (" + std::to_string(http_cap) +
          ") reached, all busy: refused one");
      return refuse(std::move(socket));
    }
    log("HTTP connection limit (" + std::to_string(http_cap) +
        ") reached: closed the oldest idle one");
  }
  std::make_shared<HttpConnection>(std::move(socket), *this)->read();
}

// The oldest connection still waiting for (the rest of) a request makes room for a new one, so
// half-sent requests cannot lock pages out.
bool Server::Impl::evict_idle_http() {
  const auto it = std::find_if(http_connections.begin(), http_connections.end(),
                               [](const HttpConnection* c) { return c->waiting_for_request(); });
  if (it == http_connections.end()) return false;
  (*it)->evict();
  return true;
}

void Server::Impl::log(const std::string& line) {
  int dropped = 0;
  const bool admitted = log_limit.admit(Clock::now(), dropped);
  if (dropped > 0) log_line(std::to_string(dropped) + " more log lines suppressed");
  if (admitted) log_line(line);
}

void Server::Impl::handle_message(const std::shared_ptr<Client>& client, std::string_view text) {
  const Session::Reply reply = session.handle(text);
  if (!reply.ok) client->log("bad message: " + reply.log);
  client->send(std::make_shared<const std::string>(reply.text), false);
  if (reply.scene_changed) {
    log("scene " + session.scene_name() + " loaded");
    broadcast_scene();
  }
}

void Server::Impl::broadcast_scene() {
  const auto message = std::make_shared<const std::string>(session.scene_message());
  for (const auto& c : std::vector<std::shared_ptr<Client>>(clients.begin(), clients.end())) {
    c->positions_sent.reset();
    c->send(message, false);
  }
}

void Server::Impl::tick() {
  try {
    session.tick();
    const auto snapshot = session.snapshot();
    const auto state = std::make_shared<const std::string>(
        session.state_message(static_cast<int>(clients.size())));
    std::shared_ptr<const std::string> positions;
    for (const auto& c : std::vector<std::shared_ptr<Client>>(clients.begin(), clients.end())) {
      c->send(state, false, true);
      if (c->positions_sent == snapshot || c->behind()) continue;
      if (!positions) positions = std::make_shared<const std::string>(positions_frame(*snapshot));
      c->positions_sent = snapshot;
      c->send(positions, true, true);
    }
  } catch (const std::exception& e) {
    log(std::string("streaming failed: ") + e.what());
  }
  if (const int dropped = log_limit.take_dropped(Clock::now()); dropped > 0)
    log_line(std::to_string(dropped) + " more log lines suppressed");
  // Fixed-rate schedule; after a stall, start again from now rather than bursting.
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / options.state_rate));
  next_tick += period;
  if (next_tick < Clock::now()) next_tick = Clock::now() + period;
  ticker.expires_at(next_tick);
  ticker.async_wait([self = shared_from_this()](beast::error_code ec) {
    if (!ec) self->tick();
  });
}

void Server::Impl::close_all_and_stop() {
  for (const auto& c : std::vector<std::shared_ptr<Client>>(clients.begin(), clients.end()))
    c->go_away();
  // Long enough for the close frames to leave on a local network, short against the 1 s in
  // which serve must stop after SIGINT.
  goodbye_timer.expires_after(std::chrono::milliseconds(150));
  goodbye_timer.async_wait([this](beast::error_code) { ioc.stop(); });
}

Server::Server(Session& session, ServerOptions options)
    : impl_(std::make_shared<Impl>(session, std::move(options))) {
  auto& a = impl_->acceptor;
  beast::error_code ec;
  const auto address = net::ip::make_address(impl_->options.host, ec);
  if (ec) throw InputError("serve", "--host", "an IP address", impl_->options.host);
  const tcp::endpoint endpoint(address, impl_->options.port);
  a.open(endpoint.protocol(), ec);
  if (!ec) a.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) a.bind(endpoint, ec);
  if (!ec) a.listen(net::socket_base::max_listen_connections, ec);
  if (ec)
    throw InputError("serve", impl_->options.host + ":" + std::to_string(impl_->options.port),
                     "cannot listen: " + ec.message());
}

Server::~Server() { stop(); }

unsigned short Server::port() const { return impl_->acceptor.local_endpoint().port(); }

std::string Server::url() const {
  const auto address = impl_->acceptor.local_endpoint().address();
  const std::string host = address.is_v6() ? "[" + address.to_string() + "]" : address.to_string();
  return "http://" + host + ":" + std::to_string(port()) + "/";
}

void Server::run() {
  impl_->signals.async_wait([impl = impl_](beast::error_code ec, int) {
    if (!ec) impl->close_all_and_stop();
  });
  impl_->accept();
  impl_->next_tick = Clock::now();
  impl_->tick();
  impl_->ioc.run();
}

void Server::stop() { impl_->ioc.stop(); }

}  // namespace shapectl::server
