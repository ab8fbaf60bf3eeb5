// The one error type the library throws. Its message names where the problem is
// (file and line or byte, device and command) so the CLI can print it as is.
#pragma once

#include <stdexcept>
#include <string>

namespace mlmap {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace mlmap
