// Input files are regular files: a device or a pipe named as one is refused before it is
// opened, since a reader that reads to the end never reaches it (/dev/zero) and opening a
// pipe waits for its writer.
#pragma once

#include <filesystem>

namespace mlmap::io {

// Throws mlmap::Error "path: no such file" or "path: not a regular file".
void requireRegularFile(const std::filesystem::path& path);

// Throws mlmap::Error "path: not a regular file" where the path exists and is no regular
// file; a missing path is left to the caller's own open error.
void refuseNonRegularFile(const std::filesystem::path& path);

}  // namespace mlmap::io
