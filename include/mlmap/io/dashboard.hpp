// The web dashboard, exported beside its data so it opens from disk (file://) or
// from any static server: the built page (web/dist/index.html, self-contained) as
// DIR/index.html, the planes as DIR/planes.json, and the same JSON as DIR/planes.js
// (`window.MLMAP_PLANES = ...;`), which the page loads with a plain script tag because
// browsers refuse fetch() on file:// pages. The blocks likewise: DIR/blocks.bin
// (io/dashboard_blocks.hpp) and DIR/blocks.js (`window.MLMAP_BLOCKS = "<base64>";`), and
// when asked for, the occupied voxels: DIR/voxels.bin (io/dashboard_voxels.hpp) and
// DIR/voxels.js (`window.MLMAP_VOXELS = "<base64>";`).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace mlmap::io {

// Each file written atomically; DIR is created when missing. Throws mlmap::Error
// when the page cannot be read. Empty voxels_binary: no voxel layer, and the voxel
// files of an earlier export into DIR are removed (the page would show them).
void writeDashboard(const std::filesystem::path& directory, const std::filesystem::path& page,
                    const std::string& planes_json, const std::string& blocks_binary,
                    const std::string& voxels_binary = {});

// RFC 4648 base64 with padding, as the page's atob() reads it.
std::string base64(std::string_view bytes);

}  // namespace mlmap::io
