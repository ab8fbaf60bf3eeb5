#include "mlmap/driver/ptu.hpp"

#include <charconv>
#include <cstdlib>

namespace mlmap::driver {
namespace {

char axisLetter(PtuAxis which) { return which == PtuAxis::Pan ? 'P' : 'T'; }

std::string trimmed(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\r')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\r')) text.remove_suffix(1);
  return std::string(text);
}

bool isAsyncLimit(std::string_view line) {
  return line == "!P" || line == "!T" || line.find("limit") != std::string_view::npos;
}

}  // namespace

PtuClient::PtuClient(Transport& transport, std::chrono::milliseconds timeout)
    : transport_(transport), reader_(transport), timeout_(timeout) {}

std::string PtuClient::reply(const std::string& command, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (int lines = 0; lines < 64; ++lines) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    const auto line = reader_.readLine(std::max(left, std::chrono::milliseconds(0)), 512);
    if (!line) {
      throw PtuError(PtuError::Kind::Timeout,
                     transport_.name() + ": " + command + ": no answer within " +
                         std::to_string(timeout.count()) + " ms");
    }
    // With echo on, the command precedes the reply on its line: start at '*' or '!'.
    const auto start = line->find_first_of("*!");
    if (start == std::string::npos) continue;
    const std::string text = trimmed(std::string_view(*line).substr(start));
    if (text[0] == '*') {
      last_replied_ = transport_.now();
      return trimmed(std::string_view(text).substr(1));
    }
    if (isAsyncLimit(text)) {
      throw PtuError(PtuError::Kind::Limit,
                     transport_.name() + ": " + (text == "!P" ? "pan" : "tilt") +
                         " limit hit (asynchronous " + text + ") during " + command);
    }
    throw PtuError(PtuError::Kind::Refused,
                   transport_.name() + ": " + command + ": refused: " + trimmed(text.substr(1)));
  }
  throw PtuError(PtuError::Kind::Malformed, transport_.name() + ": " + command + ": no reply line");
}

std::string PtuClient::exchange(const std::string& command, std::chrono::milliseconds timeout) {
  transport_.write(command + " ");
  last_sent_ = transport_.now();
  return reply(command, timeout);
}

int PtuClient::queryInt(const std::string& command) {
  const std::string text = exchange(command, timeout_);
  // Verbose feedback words the value ("Current Pan position is 100"): take the last number.
  const auto end = text.find_last_of("0123456789");
  if (end == std::string::npos) {
    throw PtuError(PtuError::Kind::Malformed, transport_.name() + ": " + command + ": no number in '" + text + "'");
  }
  auto begin = text.find_last_not_of("0123456789", end);
  begin = begin == std::string::npos ? 0 : begin + 1;
  if (begin > 0 && text[begin - 1] == '-') --begin;
  int value = 0;
  const auto [ptr, error] = std::from_chars(text.data() + begin, text.data() + end + 1, value);
  if (error != std::errc() || ptr != text.data() + end + 1) {
    throw PtuError(PtuError::Kind::Malformed, transport_.name() + ": " + command + ": bad number in '" + text + "'");
  }
  return value;
}

void PtuClient::initialise() {
  exchange("ED", timeout_);  // echo off
  exchange("FT", timeout_);  // terse feedback
  exchange("I", timeout_);
  for (PtuAxis which : {PtuAxis::Pan, PtuAxis::Tilt}) {
    const std::string letter(1, axisLetter(which));
    const std::string text = exchange(letter + "R", timeout_);
    // "185.1428" or "185.1428 seconds arc per position"
    char* end = nullptr;
    const double arcsec = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || !(arcsec > 0.0) || arcsec > 36000.0) {
      throw PtuError(PtuError::Kind::Malformed, transport_.name() + ": " + letter + "R: bad resolution '" + text + "'");
    }
    PtuAxisInfo& info = which == PtuAxis::Pan ? pan_ : tilt_;
    info.resolution_arcsec = arcsec;
    info.min_position = queryInt(letter + "N");
    info.max_position = queryInt(letter + "X");
    if (info.min_position > info.max_position) {
      throw PtuError(PtuError::Kind::Malformed, transport_.name() + ": " + letter + "N > " + letter + "X");
    }
  }
}

void PtuClient::setPosition(PtuAxis which, int position) {
  const PtuAxisInfo& info = axis(which);
  if (info.resolution_arcsec > 0.0 && (position < info.min_position || position > info.max_position)) {
    throw PtuError(PtuError::Kind::Refused,
                   transport_.name() + ": " + axisLetter(which) + "P" + std::to_string(position) +
                       ": outside the limits [" + std::to_string(info.min_position) + ", " +
                       std::to_string(info.max_position) + "]");
  }
  exchange(std::string(1, axisLetter(which)) + "P" + std::to_string(position), timeout_);
}

int PtuClient::position(PtuAxis which) { return queryInt(std::string(1, axisLetter(which)) + "P"); }
void PtuClient::setSpeed(PtuAxis which, int value) {
  exchange(std::string(1, axisLetter(which)) + "S" + std::to_string(value), timeout_);
}
int PtuClient::speed(PtuAxis which) { return queryInt(std::string(1, axisLetter(which)) + "S"); }
void PtuClient::setBaseSpeed(PtuAxis which, int value) {
  exchange(std::string(1, axisLetter(which)) + "B" + std::to_string(value), timeout_);
}
int PtuClient::baseSpeed(PtuAxis which) { return queryInt(std::string(1, axisLetter(which)) + "B"); }
void PtuClient::setAcceleration(PtuAxis which, int value) {
  exchange(std::string(1, axisLetter(which)) + "A" + std::to_string(value), timeout_);
}
int PtuClient::acceleration(PtuAxis which) { return queryInt(std::string(1, axisLetter(which)) + "A"); }
void PtuClient::immediateMode() { exchange("I", timeout_); }
void PtuClient::slavedMode() { exchange("S", timeout_); }

void PtuClient::await(std::chrono::milliseconds timeout) { exchange("A", timeout); }

void PtuClient::startAwait() {
  transport_.write("A ");
  last_sent_ = transport_.now();
  pending_await_ = "A";
}

bool PtuClient::awaitDone(std::chrono::milliseconds timeout) {
  if (pending_await_.empty()) return true;
  try {
    reply("A", timeout);
  } catch (const PtuError& error) {
    if (error.kind() == PtuError::Kind::Timeout) return false;
    pending_await_.clear();
    throw;
  }
  pending_await_.clear();
  return true;
}

}  // namespace mlmap::driver
