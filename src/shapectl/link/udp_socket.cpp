#include <shapectl/link/udp_socket.hpp>

#include <arpa/inet.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <shapectl/io/input_error.hpp>

namespace shapectl {

sockaddr_in ipv4_address(const std::string& host, int port, const std::string& what) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  const std::string h = host == "localhost" ? "127.0.0.1" : host;
  if (inet_pton(AF_INET, h.c_str(), &a.sin_addr) != 1)
    throw InputError(what, "", "an IPv4 address", "'" + host + "'");
  return a;
}

UdpSocket::UdpSocket(const std::string& address, int port, const std::string& what) {
  if (port < 0 || port > 65535) throw InputError(what, "", "a port 0..65535", port);
  const sockaddr_in a = ipv4_address(address, port, what);
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0)
    throw InputError(what, "", std::string("cannot create a socket: ") + std::strerror(errno));
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0) {
    const std::string error = std::strerror(errno);
    ::close(fd_);
    throw InputError(what, "",
                     "cannot bind " + address + ":" + std::to_string(port) + ": " + error);
  }
  sockaddr_in bound{};
  socklen_t size = sizeof bound;
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&bound), &size);
  port_ = ntohs(bound.sin_port);
}

UdpSocket::~UdpSocket() {
  if (fd_ >= 0) ::close(fd_);
}

UdpSocket::UdpSocket(UdpSocket&& other) noexcept : fd_(other.fd_), port_(other.port_) {
  other.fd_ = -1;
}

long UdpSocket::receive(std::span<char> buffer, sockaddr_in* from) {
  sockaddr_in sender{};
  socklen_t size = sizeof sender;
  // MSG_TRUNC: the datagram's real length, so oversized ones are recognised, not misread.
  const ssize_t n = ::recvfrom(fd_, buffer.data(), buffer.size(), MSG_TRUNC,
                               reinterpret_cast<sockaddr*>(&sender), &size);
  if (n < 0) return -1;
  if (from) *from = sender;
  return static_cast<long>(n);
}

long UdpSocket::receive(std::span<char> buffer, sockaddr_in* from, double* arrived) {
  sockaddr_in sender{};
  iovec io{buffer.data(), buffer.size()};
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec))];
  msghdr message{};
  message.msg_name = &sender;
  message.msg_namelen = sizeof sender;
  message.msg_iov = &io;
  message.msg_iovlen = 1;
  message.msg_control = control;
  message.msg_controllen = sizeof control;
  const ssize_t n = ::recvmsg(fd_, &message, MSG_TRUNC);
  if (n < 0) return -1;
  if (from) *from = sender;
  *arrived = 0;
  for (cmsghdr* c = CMSG_FIRSTHDR(&message); c; c = CMSG_NXTHDR(&message, c))
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
      timespec t;
      std::memcpy(&t, CMSG_DATA(c), sizeof t);
      *arrived = static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
    }
  return static_cast<long>(n);
}

void UdpSocket::record_arrival_times() {
  const int on = 1;
  ::setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);
}

bool UdpSocket::send_to(std::string_view bytes, const sockaddr_in& to) {
  return ::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&to),
                  sizeof to) == static_cast<ssize_t>(bytes.size());
}

}  // namespace shapectl
