// XYZ text scans: one point per line, "x y z [label]", '#' starts a comment.
// A fourth column is kept as an integer label (ground truth or plane id).
#pragma once

#include <filesystem>

#include "mlmap/scan.hpp"

namespace mlmap::io {

// Points as written (no pose). Labels are filled when every point line has a 4th
// column that is an integer; columns after the 4th are ignored. A non-integer 4th
// column (an intensity such as 0.53) makes the file unlabelled; a 4th column on
// some point lines but not on others is an error. Throws mlmap::Error naming
// "file:line" for anything malformed, and for a file without points.
Scan readXyz(const std::filesystem::path& path);

// Writes scan.points as they are ("x y z" or "x y z label" when scan.labels is set),
// coordinates to 6 decimals (1 µm), through writeAtomically.
void writeXyz(const std::filesystem::path& path, const Scan& scan);

}  // namespace mlmap::io
