// OctoMap reports on std::cerr ("Reading octree type OcTree", warnings on bad
// input); the library never prints, so its calls run with std::cerr captured, and
// what it said can go into an error message.
#pragma once

#include <iostream>
#include <sstream>
#include <string>

namespace mlmap::io {

class CapturedCerr {
 public:
  CapturedCerr() : previous_(std::cerr.rdbuf(captured_.rdbuf())) {}
  ~CapturedCerr() { std::cerr.rdbuf(previous_); }
  CapturedCerr(const CapturedCerr&) = delete;
  CapturedCerr& operator=(const CapturedCerr&) = delete;

  // What was written, on one line.
  std::string text() const {
    std::string result = captured_.str();
    for (char& c : result) {
      if (c == '\n') c = ' ';
    }
    return result;
  }

 private:
  std::ostringstream captured_;
  std::streambuf* previous_;
};

}  // namespace mlmap::io
