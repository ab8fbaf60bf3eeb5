// mlmap_bench: the speed and size figures of the README, printed, never asserted.
//   mlmap_bench [SCENE.json] [--quick]
//   mlmap_bench icp SCENE_DIR [--runs N]   (pairwise ICP, see icp_pairs.cpp)
//   mlmap_bench octree --poses POSES.txt SCAN...   (the OcTree layer alone, see octree_insert.cpp)
//   mlmap_bench pacing [SCENE.json] [--seconds S] [--time-scale X]   (emulator_pacing.cpp)
//   mlmap_bench icp-starts JOBS.json [--plain]   (ICP from given starts, see icp_starts.cpp)
// Simulates the scene (default maps/lab.json), then times insertion into the block
// layer alone and the OcTree alone on the same points, and reports map sizes at
// several cell sizes.
#include <chrono>
#include <cstdio>
#include <algorithm>
#include <cstring>
#include <fstream>
#include <string>
#include <thread>

#include "stopwatch.hpp"
#include "icp_pairs.hpp"
#include "octree_insert.hpp"
#include "icp_starts.hpp"
#include "threads.hpp"
#include "mlmap/map/map.hpp"
#include "mlmap/sim/scene.hpp"
#include "mlmap/sim/simulator.hpp"

namespace mlmap::bench {
int runPacing(int argc, char** argv);
}

namespace {

using mlmap::bench::Clock;
using mlmap::bench::secondsSince;

// Peak resident memory of this process so far, in MB (Linux VmHWM).
double peakMemoryMb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && std::strcmp(argv[1], "pacing") == 0) {
    try {
      return mlmap::bench::runPacing(argc - 1, argv + 1);
    } catch (const std::exception& error) {
      std::fprintf(stderr, "mlmap_bench pacing: %s\n", error.what());
      return 1;
    }
  }
  if (argc > 1 && std::strcmp(argv[1], "icp") == 0) {
    try {
      return mlmap::bench::runIcpPairs(argc - 1, argv + 1);
    } catch (const std::exception& error) {
      std::fprintf(stderr, "mlmap_bench icp: %s\n", error.what());
      return 1;
    }
  }
  if (argc > 1 && std::strcmp(argv[1], "octree") == 0) return mlmap::bench::runOctreeInsert(argc - 1, argv + 1);
  if (argc > 1 && std::strcmp(argv[1], "icp-starts") == 0) {
    try {
      return mlmap::bench::runIcpStarts(argc - 1, argv + 1);
    } catch (const std::exception& error) {
      std::fprintf(stderr, "mlmap_bench icp-starts: %s\n", error.what());
      return 1;
    }
  }
  std::string scene_path = std::string(MLMAP_SOURCE_DIR) + "/maps/lab.json";
  bool quick = false;
  for (int k = 1; k < argc; ++k) {
    if (std::strcmp(argv[k], "--quick") == 0) {
      quick = true;
    } else if (std::strcmp(argv[k], "--help") == 0 || std::strcmp(argv[k], "-h") == 0) {
      std::printf("usage: mlmap_bench [SCENE.json] [--quick]\n       mlmap_bench icp SCENE_DIR [--runs 3]\n");
      return 0;
    } else {
      scene_path = argv[k];
    }
  }
  try {
    const auto scene = mlmap::sim::loadScene(scene_path);
    auto start = Clock::now();
    const auto simulated = mlmap::sim::simulate(scene);
    const double simulate_seconds = secondsSince(start);
    std::vector<mlmap::Scan> scans;
    std::size_t points = 0;
    for (const auto& s : simulated) {
      scans.push_back(s.scan);
      points += s.scan.size();
    }
    std::printf("mlmap_bench: %s, %zu poses, %zu points, %d threads, %u hardware threads\n",
                scene.name.c_str(), scans.size(), points, mlmap::bench::threadCount(),
                std::thread::hardware_concurrency());
    std::printf("  simulate                  %8.3f s  (%.1f M points/s)\n", simulate_seconds,
                static_cast<double>(points) / simulate_seconds / 1e6);

    // OctoMap's own insertPointCloud is the reference a user would otherwise call.
    std::vector<octomap::Pointcloud> clouds(scans.size());
    for (std::size_t k = 0; k < scans.size(); ++k) {
      for (std::size_t p = 0; p < scans[k].size(); ++p) {
        const Eigen::Vector3d world = scans[k].worldPoint(p);
        clouds[k].push_back(static_cast<float>(world.x()), static_cast<float>(world.y()),
                            static_cast<float>(world.z()));
      }
    }
    std::printf("\nInsertion, true poses: the block layer, mlmap's OcTree layer and OctoMap's own\n"
                "insertPointCloud (discretized, as the layer), each timed alone on the same points\n"
                "(Mpt/s = million points/s)\n");
    std::printf("  %-6s %9s %9s %8s %8s %8s %9s %9s %9s %9s\n", "cell", "cells", "blocks",
                "vertical", "B/block", "blocks", "OcTree", "OctoMap", "OcTree MB", "ratio");
    std::printf("  %-6s %9s %9s %8s %8s %8s %9s %9s %9s %9s\n", "m", "", "", "", "", "Mpt/s",
                "Mpt/s", "Mpt/s", "", "blk/OctoMap");
    const std::vector<double> cell_sizes = quick ? std::vector<double>{0.1}
                                                 : std::vector<double>{0.02, 0.05, 0.1};
    for (const double cell_size : cell_sizes) {
      mlmap::MapConfig config;
      config.cell_size = cell_size;
      // The block layer is timed as the best of three fresh builds: a single run of a
      // fraction of a second is at the mercy of whatever else the machine does.
      double block_seconds = 1e300;
      mlmap::Map map(config);
      for (int repeat = 0; repeat < 3; ++repeat) {
        mlmap::Map fresh(config);
        start = Clock::now();
        for (const auto& scan : scans) fresh.insertIntoBlocks(scan);
        fresh.blocks().compact();
        block_seconds = std::min(block_seconds, secondsSince(start));
        if (repeat == 2) map = std::move(fresh);
      }
      const auto stats = map.blocks().stats();
      double octree_seconds = 0.0;
      double octree_mb = 0.0;
      // Ray casting at 2 cm over a whole lab takes minutes; time it where it is affordable.
      const bool time_octree = cell_size >= 0.05;
      if (time_octree) {
        start = Clock::now();
        for (const auto& scan : scans) map.insertIntoOctree(scan);
        octree_seconds = secondsSince(start);
        map.octree().prune();
        octree_mb = static_cast<double>(map.octree().memoryUsage()) / 1e6;
      }
      double octomap_seconds = 0.0;
      if (time_octree) {
        octomap::OcTree reference(cell_size);
        start = Clock::now();
        for (std::size_t k = 0; k < scans.size(); ++k) {
          const Eigen::Vector3d origin = scans[k].pose.translation();
          // discretize = true: the semantics of mlmap's OcTree layer (one ray per end voxel).
          reference.insertPointCloud(clouds[k],
                                     octomap::point3d(static_cast<float>(origin.x()), static_cast<float>(origin.y()),
                                                      static_cast<float>(origin.z())),
                                     -1.0, false, true);
        }
        octomap_seconds = secondsSince(start);
      }
      const double million_points = static_cast<double>(points) / 1e6;
      const double block_rate = million_points / block_seconds;
      std::printf("  %-6.3g %9zu %9zu %8zu %8.1f %8.1f", cell_size, stats.cells, stats.blocks,
                  stats.vertical_blocks,
                  static_cast<double>(stats.memory_bytes) / static_cast<double>(stats.blocks), block_rate);
      if (time_octree) {
        const double octomap_rate = million_points / octomap_seconds;
        std::printf(" %9.2f %9.2f %9.1f %8.0fx\n", million_points / octree_seconds, octomap_rate,
                    octree_mb, block_rate / octomap_rate);
      } else {
        std::printf(" %9s %9s %9s %9s\n", "-", "-", "-", "-");
      }
      std::fflush(stdout);
    }
    std::printf("\n  peak resident memory      %.0f MB (includes the simulated scans)\n", peakMemoryMb());
  } catch (const std::exception& error) {
    std::fprintf(stderr, "mlmap_bench: %s\n", error.what());
    return 1;
  }
  return 0;
}
