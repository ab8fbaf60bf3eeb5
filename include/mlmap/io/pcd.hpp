// PCD v0.7 point clouds (ascii, binary, binary_compressed with LZF), as PCL writes
// them: fields x y z and an optional `label`; other fields skipped; points with a
// NaN coordinate (organized clouds' "no return") are dropped.
#pragma once

#include <filesystem>

#include "mlmap/scan.hpp"

namespace mlmap::io {

enum class PcdEncoding { Ascii, Binary, BinaryCompressed };

// scan.pose is set from VIEWPOINT.
Scan readPcd(const std::filesystem::path& path);

void writePcd(const std::filesystem::path& path, const Scan& scan,
              PcdEncoding encoding = PcdEncoding::Binary);

}  // namespace mlmap::io
