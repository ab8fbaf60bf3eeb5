#include "mlmap/driver/transport.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <termios.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

#include "mlmap/error.hpp"

namespace mlmap::driver {
namespace {

std::string systemError(const std::string& what) { return what + ": " + std::strerror(errno); }

speed_t baudConstant(int baud, const std::string& device) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 500000: return B500000;
    case 921600: return B921600;
    default: throw Error(device + ": unsupported baud rate " + std::to_string(baud));
  }
}

void makeRaw(int fd, speed_t speed, const std::string& device) {
  termios settings{};
  if (tcgetattr(fd, &settings) != 0) throw Error(systemError(device + ": tcgetattr"));
  cfmakeraw(&settings);
  settings.c_cflag |= CLOCAL | CREAD;
  settings.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | CRTSCTS);
  settings.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  settings.c_cc[VMIN] = 0;
  settings.c_cc[VTIME] = 0;
  cfsetispeed(&settings, speed);
  cfsetospeed(&settings, speed);
  if (tcsetattr(fd, TCSANOW, &settings) != 0) throw Error(systemError(device + ": tcsetattr"));
}

}  // namespace

double hostSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

FdTransport::FdTransport(int fd, std::string name) : fd_(fd), name_(std::move(name)) {
  struct stat status {};
  socket_ = ::fstat(fd_, &status) == 0 && S_ISSOCK(status.st_mode);
}

FdTransport::~FdTransport() {
  if (fd_ >= 0) ::close(fd_);
}

void FdTransport::write(std::string_view bytes) {
  last_s_ = hostSeconds();  // before the bytes leave: the device cannot answer earlier
  std::size_t done = 0;
  while (done < bytes.size()) {
    // A socket whose peer has gone must fail with EPIPE, not raise SIGPIPE and end the
    // process (an emulator whose client hung up serves the next one).
    const ssize_t written = socket_ ? ::send(fd_, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL)
                                    : ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (written < 0) {
      if (errno == EINTR) continue;
      if (errno == EAGAIN) {
        pollfd waiter{fd_, POLLOUT, 0};
        if (::poll(&waiter, 1, 1000) <= 0) throw Error(name_ + ": write timed out");
        continue;
      }
      throw Error(systemError(name_ + ": write"));
    }
    done += static_cast<std::size_t>(written);
  }
}

std::size_t FdTransport::read(char* buffer, std::size_t capacity, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    pollfd waiter{fd_, POLLIN, 0};
    const int ready = ::poll(&waiter, 1, static_cast<int>(std::max<std::int64_t>(0, left.count())));
    last_s_ = hostSeconds();  // after the bytes arrived: they were sent earlier
    if (ready < 0) {
      if (errno == EINTR) continue;
      throw Error(systemError(name_ + ": poll"));
    }
    if (ready == 0) return 0;
    const ssize_t got = ::read(fd_, buffer, capacity);
    if (got > 0) return static_cast<std::size_t>(got);
    if (got == 0) throw Error(name_ + ": device disconnected (end of stream)");
    if (errno == EINTR || errno == EAGAIN) continue;
    if (errno == EIO) throw Error(name_ + ": device disconnected (I/O error)");
    throw Error(systemError(name_ + ": read"));
  }
}

std::unique_ptr<FdTransport> openSerial(const std::string& device, int baud) {
  const speed_t speed = baudConstant(baud, device);
  const int fd = ::open(device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw Error(systemError(device + ": open"));
  auto transport = std::make_unique<FdTransport>(fd, device);
  makeRaw(fd, speed, device);
  tcflush(fd, TCIOFLUSH);
  return transport;
}

std::unique_ptr<FdTransport> connectTcp(const std::string& host, int port,
                                        std::chrono::milliseconds timeout) {
  const std::string name = "tcp:" + host + ":" + std::to_string(port);
  if (port <= 0 || port > 65535) throw Error(name + ": bad port");
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (::getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found) != 0 || !found) {
    throw Error(name + ": cannot resolve host");
  }
  std::string last_error = "no address";
  for (addrinfo* address = found; address; address = address->ai_next) {
    const int fd = ::socket(address->ai_family, address->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC,
                            address->ai_protocol);
    if (fd < 0) continue;
    auto transport = std::make_unique<FdTransport>(fd, name);
    if (::connect(fd, address->ai_addr, address->ai_addrlen) != 0 && errno != EINPROGRESS) {
      last_error = std::strerror(errno);
      continue;
    }
    pollfd waiter{fd, POLLOUT, 0};
    if (::poll(&waiter, 1, static_cast<int>(timeout.count())) <= 0) {
      last_error = "connection timed out";
      continue;
    }
    int socket_error = 0;
    socklen_t length = sizeof(socket_error);
    ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &socket_error, &length);
    if (socket_error != 0) {
      last_error = std::strerror(socket_error);
      continue;
    }
    const int one = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
    ::freeaddrinfo(found);
    return transport;
  }
  ::freeaddrinfo(found);
  throw Error(name + ": connect: " + last_error);
}

std::unique_ptr<Transport> openDevice(const std::string& spec, int baud) {
  if (spec.rfind("tcp:", 0) == 0) {
    const auto colon = spec.rfind(':');
    if (colon <= 4) throw Error(spec + ": expected tcp:HOST:PORT");
    const std::string port_text = spec.substr(colon + 1);
    char* end = nullptr;
    const long port = std::strtol(port_text.c_str(), &end, 10);
    if (port_text.empty() || *end != '\0') throw Error(spec + ": bad port '" + port_text + "'");
    return connectTcp(spec.substr(4, colon - 4), static_cast<int>(port));
  }
  return openSerial(spec, baud);
}

PtyPair openPtyPair() {
  const int master = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (master < 0) throw Error(systemError("posix_openpt"));
  auto transport = std::make_unique<FdTransport>(master, "pty master");
  if (::grantpt(master) != 0 || ::unlockpt(master) != 0) throw Error(systemError("grantpt/unlockpt"));
  char name[128];
  if (::ptsname_r(master, name, sizeof(name)) != 0) throw Error(systemError("ptsname"));
  ::fcntl(master, F_SETFL, ::fcntl(master, F_GETFL) | O_NONBLOCK);
  makeRaw(master, B115200, name);
  return {std::move(transport), name};
}

TcpListener::TcpListener(int port) {
  fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw Error(systemError("tcp listen: socket"));
  const int one = 1;
  ::setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  if (::bind(fd_, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0 ||
      ::listen(fd_, 1) != 0) {
    const std::string message = systemError("tcp listen on port " + std::to_string(port));
    ::close(fd_);
    throw Error(message);
  }
  socklen_t length = sizeof(address);
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&address), &length);
  port_ = ntohs(address.sin_port);
}

TcpListener::~TcpListener() { ::close(fd_); }

std::unique_ptr<FdTransport> TcpListener::accept(std::chrono::milliseconds timeout) {
  pollfd waiter{fd_, POLLIN, 0};
  if (::poll(&waiter, 1, static_cast<int>(timeout.count())) <= 0) return nullptr;
  const int fd = ::accept4(fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
  if (fd < 0) return nullptr;
  const int one = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
  return std::make_unique<FdTransport>(fd, "tcp client of port " + std::to_string(port_));
}

std::optional<std::string> LineReader::readLine(std::chrono::milliseconds timeout,
                                                std::size_t max_length) {
  // Gives up only when a read returns nothing: a replayed log (raw_log.hpp) then takes
  // the same path as the recorded run, whatever the wall clock does.
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::size_t scanned = 0;
  for (;;) {
    const auto newline = buffer_.find('\n', scanned);
    if (newline != std::string::npos) {
      std::string line = buffer_.substr(0, newline);
      buffer_.erase(0, newline + 1);
      return line;
    }
    scanned = buffer_.size();
    if (buffer_.size() > max_length) {
      buffer_.clear();
      throw Error(transport_.name() + ": line longer than " + std::to_string(max_length) +
                  " bytes (garbage from the device?)");
    }
    const auto left = std::max(std::chrono::milliseconds(0),
                               std::chrono::duration_cast<std::chrono::milliseconds>(
                                   deadline - std::chrono::steady_clock::now()));
    char chunk[4096];
    const std::size_t got = transport_.read(chunk, sizeof(chunk), left);
    if (got == 0) return std::nullopt;
    buffer_.append(chunk, got);
  }
}

}  // namespace mlmap::driver
