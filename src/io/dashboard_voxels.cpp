#include "mlmap/io/dashboard_voxels.hpp"

#include <cmath>
#include <cstring>

#include "file_bytes.hpp"
#include "mlmap/error.hpp"
#include "occupied_voxels.hpp"

namespace mlmap::io {
namespace {

constexpr char kMagic[8] = {'M', 'L', 'V', 'O', 'X', 'E', 'L', 'S'};
constexpr std::size_t kHeaderBytes = 24;
constexpr std::size_t kBytesPerVoxel = 16;

}  // namespace

std::string dashboardVoxels(const Map& map) {
  const double size = occupiedVoxelSize(map);
  std::vector<DashboardVoxel> voxels;
  forEachOccupiedVoxel(map, [&](const Eigen::Vector3d& centre, float, std::int32_t plane) {
    DashboardVoxel voxel;
    // Centres lie at (k + 0.5)·s: the floor is k whatever the rounding of the centre.
    for (int a = 0; a < 3; ++a) voxel.index[a] = static_cast<std::int32_t>(std::floor(centre[a] / size));
    voxel.plane = plane;
    voxels.push_back(voxel);
  });
  const std::size_t count = voxels.size();
  std::string bytes(kHeaderBytes + kBytesPerVoxel * count, '\0');
  std::memcpy(bytes.data(), kMagic, sizeof(kMagic));
  storeLittleEndian<std::uint32_t>(bytes.data() + 8, kDashboardVoxelsVersion);
  storeLittleEndian<std::uint32_t>(bytes.data() + 12, static_cast<std::uint32_t>(count));
  storeLittleEndian<double>(bytes.data() + 16, size);
  char* const columns = bytes.data() + kHeaderBytes;
  for (std::size_t k = 0; k < count; ++k) {
    for (int a = 0; a < 3; ++a) storeLittleEndian<std::int32_t>(columns + 4 * (a * count + k), voxels[k].index[a]);
    storeLittleEndian<std::int32_t>(columns + 4 * (3 * count + k), voxels[k].plane);
  }
  return bytes;
}

DashboardVoxels parseDashboardVoxels(std::string_view bytes, const std::string& name) {
  const auto fail = [&name](const std::string& what) { return Error(name + ": " + what); };
  if (bytes.size() < kHeaderBytes || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    throw fail("not an mlmap voxels file (no \"MLVOXELS\" header)");
  }
  const auto version = loadLittleEndian<std::uint32_t>(bytes.data() + 8);
  if (version != kDashboardVoxelsVersion) {
    throw fail("voxels file version " + std::to_string(version) + ", this reader knows version " +
               std::to_string(kDashboardVoxelsVersion));
  }
  const std::size_t count = loadLittleEndian<std::uint32_t>(bytes.data() + 12);
  if ((bytes.size() - kHeaderBytes) % kBytesPerVoxel != 0 || (bytes.size() - kHeaderBytes) / kBytesPerVoxel != count) {
    throw fail("the header says " + std::to_string(count) + " voxels, which take " +
               std::to_string(kHeaderBytes + kBytesPerVoxel * count) + " bytes, but the file has " +
               std::to_string(bytes.size()) + " (cut short or damaged?)");
  }
  DashboardVoxels result;
  result.voxel_size = loadLittleEndian<double>(bytes.data() + 16);
  if (!std::isfinite(result.voxel_size) || result.voxel_size <= 0.0) throw fail("the voxel size is not a positive number");
  const char* const columns = bytes.data() + kHeaderBytes;
  result.voxels.resize(count);
  for (std::size_t k = 0; k < count; ++k) {
    for (int a = 0; a < 3; ++a) result.voxels[k].index[a] = loadLittleEndian<std::int32_t>(columns + 4 * (a * count + k));
    result.voxels[k].plane = loadLittleEndian<std::int32_t>(columns + 4 * (3 * count + k));
  }
  return result;
}

}  // namespace mlmap::io
