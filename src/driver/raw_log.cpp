#include "mlmap/driver/raw_log.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "mlmap/error.hpp"
#include "mlmap/io/atomic_file.hpp"
#include "mlmap/io/regular_file.hpp"

namespace mlmap::driver {
namespace {

constexpr std::size_t kMaxRecordBytes = 64u << 20;

class Cursor {
 public:
  Cursor(const std::string& text, const std::string& file) : text_(text), file_(file) {}
  bool atEnd() const { return at_ == text_.size(); }
  [[noreturn]] void fail(const std::string& what) const {
    throw Error(file_ + ": byte " + std::to_string(at_) + ": " + what);
  }
  std::string line() {
    const auto end = text_.find('\n', at_);
    if (end == std::string::npos || end - at_ > 200) fail("expected a record header line");
    std::string result = text_.substr(at_, end - at_);
    at_ = end + 1;
    return result;
  }
  std::string bytes(std::size_t count) {
    if (text_.size() - at_ < count + 1) fail("record truncated");
    std::string result = text_.substr(at_, count);
    at_ += count;
    if (text_[at_] != '\n') fail("record does not end with a newline");
    ++at_;
    return result;
  }

 private:
  const std::string& text_;
  std::string file_;
  std::size_t at_ = 0;
};

std::size_t parseCount(const std::string& text, const Cursor& cursor) {
  if (text.empty() || text.size() > 9 || text.find_first_not_of("0123456789") != std::string::npos) {
    cursor.fail("bad byte count '" + text.substr(0, 20) + "'");
  }
  const std::size_t count = std::stoul(text);
  if (count > kMaxRecordBytes) cursor.fail("record too large");
  return count;
}

}  // namespace

void RawLog::add(Record record) { records_.push_back(std::move(record)); }

void RawLog::save(const std::filesystem::path& path) const {
  const auto& records = records_;
  io::writeAtomically(path, [&](std::ostream& out) {
    out << "mlmap-rawlog 1\nmeta " << metadata.size() << "\n" << metadata << "\n";
    char time[64];
    for (const auto& record : records) {
      std::snprintf(time, sizeof(time), "%a", record.host_s);
      out << record.device << ' ' << record.direction << ' ' << time << ' ' << record.bytes.size()
          << '\n';
      out.write(record.bytes.data(), static_cast<std::streamsize>(record.bytes.size()));
      out << '\n';
    }
  });
}

RawLog RawLog::load(const std::filesystem::path& path) {
  // Read to its end: a device or a pipe never ends (/dev/zero filled the memory).
  io::refuseNonRegularFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot open");
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  Cursor cursor(text, path.string());
  RawLog log;
  if (text.rfind("mlmap-rawlog 1\n", 0) != 0) cursor.fail("not an mlmap raw log (bad magic line)");
  cursor.line();
  const std::string meta = cursor.line();
  if (meta.rfind("meta ", 0) != 0) cursor.fail("expected 'meta <bytes>'");
  log.metadata = cursor.bytes(parseCount(meta.substr(5), cursor));
  while (!cursor.atEnd()) {
    const std::string header = cursor.line();
    Record record;
    if (header.size() < 8 || (header[0] != 'L' && header[0] != 'P') || header[1] != ' ' ||
        (header[2] != 'w' && header[2] != 'r' && header[2] != 't') || header[3] != ' ') {
      cursor.fail("bad record header '" + header.substr(0, 40) + "'");
    }
    record.device = header[0];
    record.direction = header[2];
    const auto space = header.find(' ', 4);
    if (space == std::string::npos) cursor.fail("bad record header '" + header.substr(0, 40) + "'");
    const std::string time = header.substr(4, space - 4);
    char* end = nullptr;
    record.host_s = std::strtod(time.c_str(), &end);
    if (time.empty() || *end != '\0') cursor.fail("bad host time '" + time + "'");
    record.bytes = cursor.bytes(parseCount(header.substr(space + 1), cursor));
    if (record.direction == 't' && !record.bytes.empty()) cursor.fail("a timeout record carries bytes");
    log.records_.push_back(std::move(record));
  }
  return log;
}

void RecordingTransport::write(std::string_view bytes) {
  inner_.write(bytes);
  last_s_ = inner_.now();
  log_.add({device_, 'w', last_s_, std::string(bytes)});
}

std::size_t RecordingTransport::read(char* buffer, std::size_t capacity,
                                     std::chrono::milliseconds timeout) {
  const std::size_t got = inner_.read(buffer, capacity, timeout);
  last_s_ = inner_.now();
  log_.add({device_, got ? 'r' : 't', last_s_, std::string(buffer, got)});
  return got;
}

ReplayTransport::ReplayTransport(const RawLog& log, char device, std::string name)
    : name_(std::move(name)) {
  for (auto& record : log.records()) {
    if (record.device == device) records_.push_back(record);
  }
}

const RawLog::Record& ReplayTransport::next(const char* doing) {
  if (cursor_ >= records_.size()) throw Error(name_ + ": replay: the log ends before this " + doing);
  return records_[cursor_];
}

void ReplayTransport::write(std::string_view bytes) {
  const auto& record = next("write");
  if (record.direction != 'w' || record.bytes != bytes) {
    throw Error(name_ + ": replay diverged: the client wrote '" + std::string(bytes.substr(0, 30)) +
                "' where the log has a " + (record.direction == 'w' ? "different write" : "read"));
  }
  last_s_ = record.host_s;
  ++cursor_;
}

std::size_t ReplayTransport::read(char* buffer, std::size_t capacity, std::chrono::milliseconds) {
  const auto& record = next("read");
  if (record.direction == 'w') {
    throw Error(name_ + ": replay diverged: the client reads where the log has a write");
  }
  last_s_ = record.host_s;
  if (record.direction == 't') {
    ++cursor_;
    return 0;
  }
  const std::size_t count = std::min(capacity, record.bytes.size() - partial_);
  std::memcpy(buffer, record.bytes.data() + partial_, count);
  partial_ += count;
  if (partial_ == record.bytes.size()) {
    partial_ = 0;
    ++cursor_;
  }
  return count;
}

}  // namespace mlmap::driver
