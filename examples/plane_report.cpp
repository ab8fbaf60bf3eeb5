// The library in a few lines: scans in, an ML map, its planes out.
//   plane_report CELL_SIZE SCAN...   (scans in the world frame, or carrying their pose)
#include <cstdio>
#include <exception>
#include <string>

#include <mlmap/error.hpp>
#include <mlmap/io/scan_file.hpp>
#include <mlmap/map/ml_map.hpp>
#include <mlmap/planes/ermsm.hpp>
#include <mlmap/planes/plane.hpp>

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s CELL_SIZE SCAN...\n", argv[0]);
    return 2;
  }
  try {
    mlmap::MLMap map(std::stod(argv[1]));
    for (int k = 2; k < argc; ++k) {
      for (const mlmap::Scan& scan : mlmap::io::readScans(argv[k])) map.insertScan(scan);
    }
    const mlmap::PlaneDetection detection = mlmap::detectPlanes(map);
    for (const mlmap::Plane& plane : detection.planes) {
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
