#include "mlmap/io/block_ply.hpp"

#include <string>
#include <unordered_map>

#include "file_bytes.hpp"
#include "mlmap/io/palette.hpp"

namespace mlmap::io {

void writeBlocksPly(const std::filesystem::path& path, const Map& map) {
  const MLMap& blocks = map.blocks();
  std::unordered_map<std::int32_t, Eigen::Vector3f> normals;
  if (map.planes()) {
    for (const Plane& plane : map.planes()->planes) normals[plane.id] = plane.normal.cast<float>();
  }
  // In the map's frame: float x y z hold a national grid's coordinates to half a metre only.
  const Eigen::Vector3d& origin = map.config().origin;
  const std::string origin_comment =
      origin.isZero() ? std::string()
                      : "comment in the map's frame, whose origin lies at " + std::to_string(origin.x()) + " " +
                            std::to_string(origin.y()) + " " + std::to_string(origin.z()) + " m\n";
  std::string out = "ply\nformat binary_little_endian 1.0\ncomment mlmap blocks, cell size " +
                    std::to_string(blocks.cellSize()) + " m\n" + origin_comment + "element vertex " +
                    std::to_string(blocks.blockCount()) +
                    "\nproperty float x\nproperty float y\nproperty float z\n"
                    "property float nx\nproperty float ny\nproperty float nz\n"
                    "property int label\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
                    "property float depth\nproperty uchar vertical\nend_header\n";
  constexpr std::size_t kVertexBytes = 6 * 4 + 4 + 3 + 4 + 1;
  out.reserve(out.size() + blocks.blockCount() * kVertexBytes);
  char vertex[kVertexBytes];
  for (std::size_t n = 0; n < blocks.cellCount(); ++n) {
    const Eigen::Vector2d xy = blocks.cellCenter(blocks.cellAt(n));
    for (const Block& block : blocks.blocksAt(n)) {
      const auto found = normals.find(block.plane);
      const Eigen::Vector3f normal = found != normals.end() ? found->second : Eigen::Vector3f::Zero();
      const Rgb colour = planeColour(block.plane);
      char* at = vertex;
      const auto put_float = [&at](double value) {
        storeLittleEndian<float>(at, static_cast<float>(value));
        at += 4;
      };
      put_float(xy.x());
      put_float(xy.y());
      put_float(block.height - block.depth / 2.0);
      put_float(normal.x());
      put_float(normal.y());
      put_float(normal.z());
      storeLittleEndian<std::int32_t>(at, block.plane);
      at += 4;
      *at++ = static_cast<char>(colour.red);
      *at++ = static_cast<char>(colour.green);
      *at++ = static_cast<char>(colour.blue);
      put_float(block.depth);
      *at++ = static_cast<char>(block.isVertical() ? 1 : 0);
      out.append(vertex, kVertexBytes);
    }
  }
  writeWholeFile(path, out);
}

}  // namespace mlmap::io
