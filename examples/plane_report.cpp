// The library in a few lines: scans in, an ML map, its planes out.
//   plane_report CELL_SIZE [--poses POSES.txt] SCAN...
// Scans carry their pose (PCD VIEWPOINT, 3DTK .pose, .graph), take pose i of the TUM
// file, or are in the world frame already (XYZ, PLY: they sit at the origin).
#include <cstdio>
#include <exception>
#include <string>

#include <mlmap/error.hpp>
#include <mlmap/io/scan_input.hpp>
#include <mlmap/map/map_planes.hpp>
#include <mlmap/planes/plane.hpp>

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s CELL_SIZE [--poses POSES.txt] SCAN...\n", argv[0]);
    return 2;
  }
  try {
    mlmap::MapConfig config;
    config.cell_size = std::stod(argv[1]);
    config.with_octree = false;
    mlmap::io::ScanInput input;
    input.identity = true;
    // A world-frame cloud has no scanner at its origin to measure ranges from; scans in
    // their sensor frame would keep the default limits (0.4-30 m: no-return readings).
    input.range = {.min = 0.0, .max = 1e9};
    for (int k = 2; k < argc; ++k) {
      if (std::string(argv[k]) == "--poses" && k + 1 < argc) {
        input.poses = argv[++k];
      } else {
        input.files.emplace_back(argv[k]);
      }
    }
    mlmap::Map map(config);
    mlmap::io::ScanSequence(input).forEach([&](mlmap::Scan& scan, std::size_t, std::size_t) { map.insertScan(scan); });
    for (const mlmap::Plane& plane : mlmap::detectPlanes(map).planes) {
      std::printf("%3d %-8s %7.2f m²  n = (%6.3f %6.3f %6.3f)  d = %7.3f m\n", plane.id,
                  std::string(mlmap::className(plane.label)).c_str(), plane.area, plane.normal.x(),
                  plane.normal.y(), plane.normal.z(), plane.offset);
    }
  } catch (const mlmap::Error& error) {
    std::fprintf(stderr, "%s\n", error.what());
    return 1;
  } catch (const std::exception& error) {  // std::stod
    std::fprintf(stderr, "bad cell size '%s': %s\n", argv[1], error.what());
    return 2;
  }
}
