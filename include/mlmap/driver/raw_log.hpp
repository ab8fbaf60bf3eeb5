// Raw logs: every byte exchanged with the laser and the pan-tilt unit, with the host time
// of each transfer, so a 3D scan can be rebuilt later by running the same client code on
// the recorded bytes (section III's acquisition, bit for bit). A read that returned
// nothing is recorded too: the replay then takes exactly the recorded path. Not
// thread-safe: one thread drives both devices.
//
// File: "mlmap-rawlog 1\n", "meta <n>\n<n bytes of JSON>\n", then per transfer
// "<L|P> <w|r|t> <host time, C hex float> <n>\n<n bytes>\n" (w: written to the device,
// r: read from it, t: a read that timed out).
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "mlmap/driver/transport.hpp"

namespace mlmap::driver {

class RawLog {
 public:
  struct Record {
    char device = 'L';     // 'L' laser, 'P' pan-tilt unit
    char direction = 'r';  // 'w', 'r', 't'
    double host_s = 0.0;
    std::string bytes;
  };

  void add(Record record);
  const std::vector<Record>& records() const { return records_; }
  std::string metadata;  // JSON describing the acquisition (options, pose)

  // Atomic write; throws mlmap::Error naming the file.
  void save(const std::filesystem::path& path) const;
  // Throws mlmap::Error naming the file and byte offset on anything malformed.
  static RawLog load(const std::filesystem::path& path);

 private:
  std::vector<Record> records_;
};

// Passes everything through to `inner` and records it in `log` as `device`.
class RecordingTransport : public Transport {
 public:
  RecordingTransport(Transport& inner, RawLog& log, char device)
      : inner_(inner), log_(log), device_(device) {}
  void write(std::string_view bytes) override;
  std::size_t read(char* buffer, std::size_t capacity, std::chrono::milliseconds timeout) override;
  double now() const override { return last_s_; }
  const std::string& name() const override { return inner_.name(); }

 private:
  Transport& inner_;
  RawLog& log_;
  char device_;
  double last_s_ = 0.0;
};

// Plays back `device`'s records: writes must match the recorded bytes (else mlmap::Error:
// the replay diverged), reads return the recorded bytes or time out where the log did;
// now() is the recorded time. Past the end of the log, writes and reads throw.
class ReplayTransport : public Transport {
 public:
  ReplayTransport(const RawLog& log, char device, std::string name);
  void write(std::string_view bytes) override;
  std::size_t read(char* buffer, std::size_t capacity, std::chrono::milliseconds timeout) override;
  double now() const override { return last_s_; }
  const std::string& name() const override { return name_; }

 private:
  const RawLog::Record& next(const char* doing);

  std::vector<RawLog::Record> records_;
  std::size_t cursor_ = 0;
  std::size_t partial_ = 0;  // bytes of records_[cursor_] already returned
  std::string name_;
  double last_s_ = 0.0;
};

}  // namespace mlmap::driver
