// mlmap_bench octree --poses POSES.txt [--resolution 0.05] [--max-range -1] [--exact-rays] SCAN...
// Scan k takes the k-th pose, as octomap_insert does. Times Map::insertIntoOctree only
// (the block layer is not built); "insert" includes nothing else.
#include "octree_insert.hpp"

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "mlmap/io/scan_file.hpp"
#include "mlmap/io/tum_poses.hpp"
#include "mlmap/map/map.hpp"
#include "stopwatch.hpp"
#include "threads.hpp"

namespace mlmap::bench {

int runOctreeInsert(int argc, char** argv) try {
  std::string poses_path;
  MapConfig config;
  config.cell_size = 0.05;
  std::vector<std::string> files;
  for (int k = 1; k < argc; ++k) {
    const std::string argument = argv[k];
    const bool has_value = k + 1 < argc;
    if (argument == "--poses" && has_value) {
      poses_path = argv[++k];
    } else if (argument == "--resolution" && has_value) {
      config.cell_size = std::stod(argv[++k]);
    } else if (argument == "--max-range" && has_value) {
      config.max_range = std::stod(argv[++k]);
    } else if (argument == "--exact-rays") {
      config.exact_rays = true;
    } else {
      files.push_back(argument);
    }
  }
  if (poses_path.empty() || files.empty()) {
    std::fprintf(stderr, "usage: mlmap_bench octree --poses POSES.txt [--resolution 0.05] [--max-range -1] "
                         "[--exact-rays] SCAN...\n");
    return 2;
  }
  const auto poses = io::readTumPoses(poses_path);
  Map map(config);
  double read_seconds = 0.0;
  double insert_seconds = 0.0;
  double insert_cpu_seconds = 0.0;
  std::size_t points = 0;
  std::size_t index = 0;
  for (const std::string& file : files) {
    auto start = Clock::now();
    std::vector<Scan> scans = io::readScans(file);
    read_seconds += std::chrono::duration<double>(Clock::now() - start).count();
    for (Scan& scan : scans) {
      if (index >= poses.size()) throw std::runtime_error("fewer poses than scans");
      scan.pose = poses[index++].pose;
      points += scan.size();
      start = Clock::now();
      const double cpu_start = processCpuSeconds();
      map.insertIntoOctree(scan);
      insert_seconds += std::chrono::duration<double>(Clock::now() - start).count();
      insert_cpu_seconds += processCpuSeconds() - cpu_start;
    }
  }
  const octomap::OcTree& tree = map.octree();
  std::printf("{\"peer\": \"mlmap_octree\", \"threads\": %d, \"scans\": %zu, \"points\": %zu, \"exact_rays\": %s,\n"
              " \"tree\": {\"nodes\": %zu, \"leaf_nodes\": %zu, \"memory_usage_bytes\": %zu},\n"
              " \"points_per_s\": %.0f,\n \"seconds\": {\"read\": %.3f, \"insert\": %.3f, \"insert_cpu\": %.3f}}\n",
              threadCount(), index, points, config.exact_rays ? "true" : "false", tree.size(),
              tree.getNumLeafNodes(), tree.memoryUsage(), static_cast<double>(points) / insert_seconds,
              read_seconds, insert_seconds, insert_cpu_seconds);
  return 0;
} catch (const std::exception& error) {
  std::fprintf(stderr, "mlmap_bench octree: %s\n", error.what());
  return 1;
}

}  // namespace mlmap::bench
