#pragma once
// A non-blocking IPv4 UDP socket, just enough for EGM: bind, receive one datagram with its
// true size and sender, send to an address.
#include <netinet/in.h>

#include <span>
#include <string>
#include <string_view>

namespace shapectl {

// InputError "<what>: '<host>' is not an IPv4 address" when it is not one.
sockaddr_in ipv4_address(const std::string& host, int port, const std::string& what);

class UdpSocket {
 public:
  // Binds `address`:`port` (port 0: any free port). InputError naming `what` on failure,
  // e.g. "egm left port: cannot bind 0.0.0.0:6511: Address already in use".
  UdpSocket(const std::string& address, int port, const std::string& what);
  ~UdpSocket();
  UdpSocket(UdpSocket&& other) noexcept;
  UdpSocket& operator=(UdpSocket&&) = delete;
  UdpSocket(const UdpSocket&) = delete;

  int fd() const { return fd_; }
  int port() const { return port_; }  // the bound port
  // The next waiting datagram into `buffer`: its full size (larger than the buffer when it was
  // cut short), or -1 when none is waiting.
  long receive(std::span<char> buffer, sockaddr_in* from);
  // The same, also telling when the kernel received it (s, CLOCK_REALTIME), after
  // record_arrival_times(); 0 when the kernel gave no time.
  long receive(std::span<char> buffer, sockaddr_in* from, double* arrived);
  void record_arrival_times();
  bool send_to(std::string_view bytes, const sockaddr_in& to);

 private:
  int fd_ = -1;
  int port_ = 0;
};

}  // namespace shapectl
