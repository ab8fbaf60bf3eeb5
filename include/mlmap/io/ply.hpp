// PLY point clouds (ascii and binary_little_endian): vertex x, y, z as float or
// double, optional integer `label`; other vertex properties and elements skipped.
#pragma once

#include <filesystem>

#include "mlmap/scan.hpp"

namespace mlmap::io {

enum class PlyEncoding { Ascii, BinaryLittleEndian };

Scan readPly(const std::filesystem::path& path);

// float x y z (+ int label when scan.labels is set).
void writePly(const std::filesystem::path& path, const Scan& scan,
              PlyEncoding encoding = PlyEncoding::BinaryLittleEndian);

}  // namespace mlmap::io
