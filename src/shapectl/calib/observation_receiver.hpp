#pragma once
// Observed frames over UDP for `run --observations-udp PORT`: one frame per datagram, in the
// frame format of OBSERVATIONS.json (calib/observations.hpp), so any camera or motion-capture
// program can feed the closed loop with a few lines of code. Never a points file (a sender
// must not make shapectl read its files); clouds go inline, within one datagram.
//
// A bad datagram (not JSON, too deep, an unknown node, non-finite numbers, joints missing or
// outside their limits) is counted as rejected and its reason kept; it never stops the loop
// and never reaches the controller.
#include <cstdint>
#include <string>
#include <vector>

#include <shapectl/calib/observations.hpp>
#include <shapectl/link/udp_socket.hpp>

namespace shapectl {

// The largest UDP payload over IPv4.
inline constexpr std::size_t max_observation_datagram = 65507;

class ObservationReceiver {
 public:
  // Binds address:port (port 0: any free one); InputError naming --observations-udp if it
  // cannot. `context` checks the frames (nodes of the mesh, the robot's joints).
  ObservationReceiver(const std::string& address, int port, ObservationContext context);
  int port() const { return socket_.port(); }

  // The frames of every datagram waiting now, in arrival order; bad ones counted.
  std::vector<ObservationFrame> receive();
  // Each datagram counts once: received (a checked frame, returned) or rejected.
  std::uint64_t received() const { return received_; }
  std::uint64_t rejected() const { return rejected_; }
  const std::string& last_rejection() const { return last_rejection_; }

 private:
  UdpSocket socket_;
  ObservationContext context_;
  std::vector<char> buffer_;
  std::uint64_t received_ = 0, rejected_ = 0;
  std::string last_rejection_;
};

}  // namespace shapectl
