// Outputs checked before the long work, so a run does not fail at its end.
#pragma once

#include <string>

namespace mlmap::cli {

// Throws mlmap::Error naming `path` unless it can be written: its directory exists and is
// writable, and it is not a directory itself.
void checkWritable(const std::string& path);

}  // namespace mlmap::cli
