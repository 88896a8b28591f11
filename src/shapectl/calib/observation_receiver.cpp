#include <shapectl/calib/observation_receiver.hpp>

#include <arpa/inet.h>

#include <shapectl/io/input_error.hpp>

namespace shapectl {

namespace {
// "udp 127.0.0.1:50123": the source named in a bad datagram's message.
std::string sender_name(const sockaddr_in& from) {
  char host[INET_ADDRSTRLEN] = "?";
  inet_ntop(AF_INET, &from.sin_addr, host, sizeof host);
  return std::string("udp ") + host + ":" + std::to_string(ntohs(from.sin_port));
}

// A frame nests 4 deep ({"markers": [{"position": [...]}]}); nothing valid nests deeper.
constexpr int max_frame_depth = 6;
}  // namespace

ObservationReceiver::ObservationReceiver(const std::string& address, int port,
                                         ObservationContext context)
    : socket_(address, port, "--observations-udp"),
      context_(context),
      buffer_(max_observation_datagram + 1) {
  context_.allow_points_files = false;
}

std::vector<ObservationFrame> ObservationReceiver::receive() {
  std::vector<ObservationFrame> frames;
  sockaddr_in from{};
  for (long size; (size = socket_.receive(buffer_, &from)) >= 0;) {
    const std::string source = sender_name(from);
    try {
      if (static_cast<std::size_t>(size) > max_observation_datagram)
        throw InputError(source, "", "a datagram of at most 65507 bytes");
      const std::string_view text(buffer_.data(), static_cast<std::size_t>(size));
      const JsonInput frame(parse_json_text(text, source,
                                            {.max_bytes = max_observation_datagram,
                                             .max_depth = max_frame_depth}),
                            source);
      frames.push_back(read_observation_frame(frame, context_));
      ++received_;
    } catch (const InputError& e) {
      ++rejected_;
      last_rejection_ = e.what();
    }
  }
  return frames;
}

}  // namespace shapectl
