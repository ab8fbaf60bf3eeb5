// Crash-safe file output: everything is written to a temporary file beside the
// target and renamed over it only once complete, so a crash or an error never
// leaves half a file under the real name.
#pragma once

#include <filesystem>
#include <fstream>
#include <functional>
#include <ostream>

namespace mlmap::io {

// Calls `write` with a stream on a temporary file; on success flushes, fsyncs and
// renames it to `path`. If `write` throws or the stream fails, the temporary file is
// removed, `path` is untouched and mlmap::Error (naming `path`) is thrown.
void writeAtomically(const std::filesystem::path& path,
                     const std::function<void(std::ostream&)>& write);

// Installs SIGINT and SIGTERM handlers that remove the temporary file of a write in
// progress, then end the process as the signal would have (for programs such as the
// CLI: Ctrl-C during a long write leaves no hidden .NAME.PID.N.tmp behind).
void removeTemporaryFilesOnSignal();

}  // namespace mlmap::io
