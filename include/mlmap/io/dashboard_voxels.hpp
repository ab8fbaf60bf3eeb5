// The map's occupied voxels for the web dashboard's voxel layer: the voxels of the octovis
// export (the OcTree's occupied leaves at its resolution, each with the plane of the block
// it falls in), as a compact binary file, "mlmap.voxels/1". Little-endian, column-wise;
// N voxels, 24 + 16·N bytes:
//
//   offset        size  what
//   0             8     magic "MLVOXELS"
//   8             4     uint32 version, 1
//   12            4     uint32 N, the number of voxels
//   16            8     float64 voxel size s, m
//   24            4·N   int32 x index: the voxel's centre x = (x index + 0.5) · s
//   24 + 4·N      4·N   int32 y index
//   24 + 8·N      4·N   int32 z index
//   24 + 12·N     4·N   int32 plane: the planes JSON's id, 0 = none
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "mlmap/map/map.hpp"

namespace mlmap::io {

constexpr std::uint32_t kDashboardVoxelsVersion = 1;

struct DashboardVoxel {
  std::array<std::int32_t, 3> index{};  // centre = (index + 0.5) · voxel size
  std::int32_t plane = 0;
};

struct DashboardVoxels {
  double voxel_size = 0.0;  // m
  std::vector<DashboardVoxel> voxels;
};

// The file's bytes: the map's occupied voxels (from its blocks at the cell size when it
// has no OcTree).
std::string dashboardVoxels(const Map& map);

// Reads the bytes back. Input is untrusted: a wrong magic or version, a size that is not
// 24 + 16·N, or a voxel size that is not a positive finite number throws mlmap::Error
// naming `name`.
DashboardVoxels parseDashboardVoxels(std::string_view bytes, const std::string& name);

}  // namespace mlmap::io
