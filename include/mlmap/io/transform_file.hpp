// A rigid transform as text (mlmap merge --transform, and what merge --register
// reports). Numbers separated by white space or new lines, '#' starts a comment:
//   4 numbers   x y z yaw_deg            (a turn about z, then the translation)
//   7 numbers   x y z qx qy qz qw        (TUM order, without the stamp)
//   16 numbers  a 4 x 4 matrix, row by row, last row 0 0 0 1
#pragma once

#include <filesystem>

#include "mlmap/scan.hpp"

namespace mlmap::io {

// Throws mlmap::Error naming the file and line for anything else, including a
// matrix whose rotation is not orthonormal.
Pose readTransform(const std::filesystem::path& path);
Pose parseTransform(std::string_view text, const std::string& name);

// The 4 x 4 matrix form, written atomically.
void writeTransform(const std::filesystem::path& path, const Pose& pose);

}  // namespace mlmap::io
