// A byte channel to a device (section III's laser and pan-tilt unit): a serial port
// (termios, raw mode; the UTM-30LX is a USB ACM device), a TCP socket (Ethernet Hokuyo
// models, port 10940) or, in tests, a pseudo-terminal. Every read has a timeout, so no
// caller can hang on a silent device. `now()` is the host time when the last write
// began or the last read ended: a reply can neither be caused before the first nor have
// arrived after the second, so the pair brackets the device's action even when the
// calling thread loses the processor between a system call and its clock reading. A
// replayed log (raw_log.hpp) gives the clients the recorded times the same way.
#pragma once

#include <chrono>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace mlmap::driver {

// Host clock in seconds (steady, arbitrary origin).
double hostSeconds();

class Transport {
 public:
  virtual ~Transport() = default;
  // Writes all of `bytes`; throws mlmap::Error naming the device when it cannot.
  virtual void write(std::string_view bytes) = 0;
  // Up to `capacity` bytes into `buffer`, waiting at most `timeout`; 0 on timeout.
  // Throws mlmap::Error when the device is gone (hang-up, end of stream, I/O error).
  virtual std::size_t read(char* buffer, std::size_t capacity, std::chrono::milliseconds timeout) = 0;
  // s, host time when the last write began or the last read ended (replay: recorded).
  virtual double now() const { return hostSeconds(); }
  // Device name for messages: "/dev/ttyACM0", "tcp:host:10940".
  virtual const std::string& name() const = 0;
};

// A file descriptor (serial port, pty side, socket) read with poll(); owns and closes it.
class FdTransport : public Transport {
 public:
  FdTransport(int fd, std::string name);
  ~FdTransport() override;
  FdTransport(const FdTransport&) = delete;
  FdTransport& operator=(const FdTransport&) = delete;

  void write(std::string_view bytes) override;
  std::size_t read(char* buffer, std::size_t capacity, std::chrono::milliseconds timeout) override;
  const std::string& name() const override { return name_; }
  double now() const override { return last_s_; }
  int fd() const { return fd_; }

 private:
  int fd_;
  std::string name_;
  bool socket_ = false;
  double last_s_ = hostSeconds();
};

// Opens a serial device in raw mode (8N1, no flow control, no echo) at `baud`
// (9600 ... 921600; ignored by USB ACM devices).
std::unique_ptr<FdTransport> openSerial(const std::string& device, int baud = 115200);

// Connects to host:port over TCP within `timeout`.
std::unique_ptr<FdTransport> connectTcp(const std::string& host, int port,
                                        std::chrono::milliseconds timeout = std::chrono::seconds(3));

// "tcp:HOST:PORT" -> connectTcp, anything else -> openSerial.
std::unique_ptr<Transport> openDevice(const std::string& spec, int baud = 115200);

// A pseudo-terminal pair (posix_openpt): the master side for an emulated device, the
// slave path for the client to open like a serial port. Both in raw mode.
struct PtyPair {
  std::unique_ptr<FdTransport> master;
  std::string slave_path;  // /dev/pts/N
};
PtyPair openPtyPair();

// A listening TCP socket on 127.0.0.1 (port 0: any free port).
class TcpListener {
 public:
  explicit TcpListener(int port = 0);
  ~TcpListener();
  TcpListener(const TcpListener&) = delete;
  TcpListener& operator=(const TcpListener&) = delete;
  int port() const { return port_; }
  // One connection, or nullptr after `timeout`.
  std::unique_ptr<FdTransport> accept(std::chrono::milliseconds timeout);

 private:
  int fd_ = -1;
  int port_ = 0;
};

// Lines over a transport: reads until '\n' with an overall timeout, keeping what follows.
class LineReader {
 public:
  explicit LineReader(Transport& transport) : transport_(transport) {}
  // The next line without its '\n' (a '\r' before it is kept), or nullopt on timeout.
  // Lines longer than `max_length` throw mlmap::Error (a device spewing garbage).
  std::optional<std::string> readLine(std::chrono::milliseconds timeout, std::size_t max_length = 4096);
  void discardBuffered() { buffer_.clear(); }
  Transport& transport() { return transport_; }

 private:
  Transport& transport_;
  std::string buffer_;
};

}  // namespace mlmap::driver
