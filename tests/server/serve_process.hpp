#pragma once
// `shapectl serve` as a child process and a page's WebSocket to it, for tests that talk to a
// real server. Every wait has a deadline, so a broken server fails a test instead of hanging it.
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio.hpp>
#include <boost/beast.hpp>

#include "support/test_support.hpp"

namespace shapectl::test {

// `serve` with `args`, its open-file limit lowered to `open_file_limit` (0: left as it is);
// stdout and stderr go to files in `dir`. Killed (SIGTERM, then SIGKILL) when the object dies.
class ServeProcess {
 public:
  ServeProcess(const TempDir& dir, const std::vector<std::string>& args, rlim_t open_file_limit = 0)
      : out_(dir.path() / "stdout"), err_(dir.path() / "stderr") {
    pid_ = test::start_process(test::cli_command(args), out_, err_, [open_file_limit] {
      const rlimit limit{open_file_limit, open_file_limit};
      if (open_file_limit > 0 && setrlimit(RLIMIT_NOFILE, &limit) != 0) _exit(126);
    });
  }
  ~ServeProcess() { stop(); }

  // The port from "open http://127.0.0.1:PORT/", or 0 if the server did not print it in time.
  int wait_for_port(std::chrono::seconds limit) {
    using namespace std::chrono_literals;
    const auto deadline = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < deadline) {
      const std::string out = read_text(out_);
      const auto at = out.find("open http://127.0.0.1:");
      if (at != std::string::npos && out.find('/', at + 22) != std::string::npos)
        return std::stoi(out.substr(at + 22));
      if (waitpid(pid_, nullptr, WNOHANG) == pid_) {
        pid_ = -1;
        return 0;
      }
      std::this_thread::sleep_for(50ms);
    }
    return 0;
  }

  // Sends `signal` and waits up to `limit` for the server to exit: the seconds it took and its
  // exit code (128 + the signal if one ended it), or nullopt if it had not exited by then.
  struct Exit {
    double seconds;
    int code;
  };
  std::optional<Exit> signal_and_wait(int signal, std::chrono::seconds limit) {
    if (pid_ <= 0) return std::nullopt;
    const auto sent = std::chrono::steady_clock::now();
    kill(pid_, signal);
    for (int status = 0; std::chrono::steady_clock::now() < sent + limit;) {
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        const std::chrono::duration<double> took = std::chrono::steady_clock::now() - sent;
        return Exit{took.count(), WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status)};
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return std::nullopt;
  }

  // True if the server was still running (and then stopped by SIGTERM in time).
  bool stop() {
    if (pid_ <= 0) return false;
    const bool exited = signal_and_wait(SIGTERM, std::chrono::seconds(10)).has_value();
    if (!exited) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    pid_ = -1;
    return exited;
  }
  std::string log() const { return read_text(err_); }
  pid_t pid() const { return pid_; }

 private:
  std::filesystem::path out_, err_;
  pid_t pid_ = -1;
};

// A page's WebSocket, read with deadlines.
class Watcher {
 public:
  explicit Watcher(int port) {
    boost::beast::get_lowest_layer(ws_).connect(
        tcp::endpoint(boost::asio::ip::address_v4::loopback(), static_cast<unsigned short>(port)));
    ws_.handshake("127.0.0.1:" + std::to_string(port), "/ws");
  }
  void send(const std::string& text) { ws_.write(boost::asio::buffer(text)); }
  // The next text message that contains `needle`, or nullopt if none came within `limit`.
  std::optional<std::string> next(const std::string& needle, std::chrono::seconds limit) {
    const auto deadline = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < deadline) {
      if (read_one(deadline)) return std::nullopt;
      if (!ws_.got_text()) continue;
      std::string text = boost::beast::buffers_to_string(buffer_.data());
      if (text.find(needle) != std::string::npos) return text;
    }
    return std::nullopt;
  }
  // Reads until the server ends the connection: its close frame's reason, or nullopt when it
  // ended without one, or nothing ended within `limit`.
  std::optional<boost::beast::websocket::close_reason> close_frame(std::chrono::seconds limit) {
    const auto deadline = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < deadline) {
      if (!read_one(deadline)) continue;
      // A close frame sets the reason; its teardown may then fail (the server has exited).
      if (ws_.reason().code != boost::beast::websocket::close_code::none) return ws_.reason();
      return std::nullopt;
    }
    return std::nullopt;
  }

 private:
  // One message into buffer_; its error, timed_out when the deadline passed first (the read
  // then cancelled).
  boost::beast::error_code read_one(std::chrono::steady_clock::time_point deadline) {
    boost::beast::error_code result = boost::asio::error::timed_out;
    buffer_.clear();
    ws_.async_read(buffer_, [&](boost::beast::error_code ec, std::size_t) { result = ec; });
    ioc_.restart();
    ioc_.run_until(deadline);
    if (!ioc_.stopped()) {  // the deadline passed with the read pending
      boost::beast::get_lowest_layer(ws_).cancel();
      ioc_.restart();
      ioc_.run();
      return boost::asio::error::timed_out;
    }
    return result;
  }

  using tcp = boost::asio::ip::tcp;
  boost::asio::io_context ioc_;
  boost::beast::websocket::stream<boost::beast::tcp_stream> ws_{ioc_};
  boost::beast::flat_buffer buffer_;
};

}  // namespace shapectl::test
