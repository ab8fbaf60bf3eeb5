// The Directed Perception pan-tilt unit (PTU-46-17.5, section III) over its ASCII
// protocol: commands like "TP-500 " are answered by a line starting with '*' (done,
// possibly followed by a value) or '!' (refused, with a reason). Positions are in the
// unit's own steps; the step size in arc-seconds is queried (PR, TR), never assumed.
// Limit hits are reported asynchronously ("!P", "!T") and end the current operation.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "mlmap/driver/transport.hpp"
#include "mlmap/error.hpp"

namespace mlmap::driver {

class PtuError : public Error {
 public:
  enum class Kind { Refused, Limit, Timeout, Malformed };
  PtuError(Kind kind, const std::string& message) : Error(message), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

enum class PtuAxis { Pan, Tilt };

struct PtuAxisInfo {
  double resolution_arcsec = 0.0;  // arc-seconds per position (PR/TR)
  int min_position = 0;            // PN/TN
  int max_position = 0;            // PX/TX
  double degreesPerPosition() const { return resolution_arcsec / 3600.0; }
};

class PtuClient {
 public:
  explicit PtuClient(Transport& transport,
                     std::chrono::milliseconds timeout = std::chrono::milliseconds(1000));

  // Echo off, terse feedback, immediate mode; queries resolution and limits of both axes.
  void initialise();
  const PtuAxisInfo& axis(PtuAxis which) const { return which == PtuAxis::Pan ? pan_ : tilt_; }

  // Position in positions; throws PtuError(Refused) outside the queried limits.
  void setPosition(PtuAxis which, int position);
  int position(PtuAxis which);
  void setSpeed(PtuAxis which, int positions_per_s);          // PS/TS
  int speed(PtuAxis which);
  void setBaseSpeed(PtuAxis which, int positions_per_s);      // PB/TB
  int baseSpeed(PtuAxis which);
  void setAcceleration(PtuAxis which, int positions_per_s2);  // PA/TA
  int acceleration(PtuAxis which);
  void immediateMode();  // I: moves start when commanded
  void slavedMode();     // S: moves wait for A
  // A: blocks (up to `timeout`) until the last commanded moves are finished.
  void await(std::chrono::milliseconds timeout);
  // Sends A without waiting; awaitDone() then polls for its '*'.
  void startAwait();
  bool awaitDone(std::chrono::milliseconds timeout);

  // Host times around the last command: when it was written and when its '*' came.
  double lastSent() const { return last_sent_; }
  double lastReplied() const { return last_replied_; }
  Transport& transport() { return transport_; }

  // Text after '*' of a reply; throws PtuError for '!' replies (and async limit errors).
  std::string exchange(const std::string& command, std::chrono::milliseconds timeout);

 private:
  std::string reply(const std::string& command, std::chrono::milliseconds timeout);
  int queryInt(const std::string& command);

  Transport& transport_;
  LineReader reader_;
  std::chrono::milliseconds timeout_;
  PtuAxisInfo pan_, tilt_;
  double last_sent_ = 0.0, last_replied_ = 0.0;
  std::string pending_await_;
};

}  // namespace mlmap::driver
