// mlmap_bench icp SCENE_DIR [--runs N] [--pairs I-J,...] [--metric point-to-plane|point-to-point]
//
// The pairs of ../shared/peers/icp_eval.py, for mlmap: source scan j, target scan i (j = i + 1
// unless --pairs), start from the odometry relative pose inv(P_odom[i])·P_odom[j]. Each pair runs
// the steps `mlmap register` runs for one scan, with its defaults (SequenceConfig): range crop and
// voxel down-sampling of both scans, the target's voxel hash and normals, then ICP. Times cover
// those steps, file reading excluded, as the peers' "total"; each is the median over --runs.
// Output: JSON on stdout; bench/icp_bench.py scores it against poses_true.txt.
#include "stopwatch.hpp"
#include "icp_pairs.hpp"
#include "threads.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mlmap/io/tum_poses.hpp"
#include "mlmap/io/xyz.hpp"
#include "mlmap/registration/icp.hpp"
#include "mlmap/registration/preprocessing.hpp"
#include "mlmap/registration/sequence_registration.hpp"
#include "mlmap/registration/voxel_hash_map.hpp"

namespace mlmap::bench {
namespace {

using namespace mlmap::registration;

// CPU seconds of every thread of this process so far: on a shared machine the wall time
// depends on the other jobs, this much less.
double processCpuSeconds() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

struct PairTimes {
  double downsample = 0.0;  // s, crop + voxel down-sampling of both scans
  double target = 0.0;      // s, voxel hash of the target + its normals
  double icp = 0.0;         // s
  double cpu = 0.0;         // s, CPU time of all threads over the three steps
  double total() const { return downsample + target + icp; }
};

struct PairRun {
  IcpResult result;
  PairTimes times;
  std::size_t target_points = 0;  // in the target's voxel hash
};

// One registration of `source` (scan j) to `target` (scan i), as SequenceRegistration does
// for a scan against its map.
PairRun registerPair(const std::vector<Point>& source, const std::vector<Point>& target, const Pose& guess,
                     const SequenceConfig& config) {
  PairRun run;
  const double cpu_start = processCpuSeconds();
  auto start = Clock::now();
  const std::vector<Point> target_dense =
      voxelDownSample(target, config.map_voxel_size / 2.0, config.min_range, config.max_range);
  const std::vector<Point> source_sample =
      voxelDownSample(source, config.source_voxel_size, config.min_range, config.max_range);
  run.times.downsample = secondsSince(start);

  start = Clock::now();
  VoxelHashMap map(config.map_voxel_size, config.max_points_per_voxel);
  map.addPoints(target_dense);
  map.estimateNormals(config.normals);
  run.times.target = secondsSince(start);
  run.target_points = map.size();

  start = Clock::now();
  run.result = alignPoints(source_sample, map, guess, config.icp);
  run.times.icp = secondsSince(start);
  run.times.cpu = processCpuSeconds() - cpu_start;
  return run;
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

nlohmann::json matrixJson(const Pose& pose) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) {
    rows.push_back({pose.matrix()(r, 0), pose.matrix()(r, 1), pose.matrix()(r, 2), pose.matrix()(r, 3)});
  }
  return rows;
}

std::string scanPath(const std::filesystem::path& scene, std::size_t index) {
  char name[32];
  std::snprintf(name, sizeof name, "scan_%03zu.xyz", index);
  return (scene / name).string();
}

}  // namespace

int runIcpPairs(int argc, char** argv) {
  std::filesystem::path scene;
  int runs = 3;
  std::string pairs_arg;
  SequenceConfig config;
  for (int k = 1; k < argc; ++k) {
    const std::string arg = argv[k];
    if (arg == "--runs" && k + 1 < argc) {
      runs = std::max(1, std::stoi(argv[++k]));
    } else if (arg == "--pairs" && k + 1 < argc) {
      pairs_arg = argv[++k];
    } else if (arg == "--metric" && k + 1 < argc) {
      config.icp.metric = std::strcmp(argv[++k], "point-to-point") == 0 ? IcpMetric::PointToPoint
                                                                         : IcpMetric::PointToPlane;
    } else if (arg == "--help" || arg == "-h") {
      std::printf("usage: mlmap_bench icp SCENE_DIR [--runs 3] [--pairs 0-1,1-2] [--metric point-to-plane]\n");
      return 0;
    } else {
      scene = arg;
    }
  }
  if (scene.empty()) {
    std::fprintf(stderr, "mlmap_bench icp: a scene directory (mlmap simulate output) is required\n");
    return 2;
  }
  const std::vector<io::StampedPose> odometry = io::readTumPoses(scene / "poses_odom.txt");
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  if (pairs_arg.empty()) {
    for (std::size_t i = 0; i + 1 < odometry.size(); ++i) {
      if (std::filesystem::exists(scanPath(scene, i + 1))) pairs.emplace_back(i, i + 1);
    }
  } else {
    std::size_t position = 0;
    while (position < pairs_arg.size()) {
      std::size_t used = 0;
      const std::size_t i = std::stoul(pairs_arg.substr(position), &used);
      position += used + 1;  // the '-'
      const std::size_t j = std::stoul(pairs_arg.substr(position), &used);
      position += used + 1;  // the ','
      pairs.emplace_back(i, j);
    }
  }

  nlohmann::json out;
  out["method"] = config.icp.metric == IcpMetric::PointToPlane ? "mlmap point-to-plane" : "mlmap point-to-point";
  out["threads"] = threadCount();
  out["runs"] = runs;
  out["config"] = {{"source_voxel", config.source_voxel_size},
                   {"map_voxel", config.map_voxel_size},
                   {"target_sample_voxel", config.map_voxel_size / 2.0},
                   {"max_points_per_voxel", config.max_points_per_voxel},
                   {"normal_radius", config.normals.radius},
                   {"initial_max_distance", config.icp.initial_max_distance}};
  out["pairs"] = nlohmann::json::array();
  for (const auto& [i, j] : pairs) {
    const std::vector<Point> target = io::readXyz(scanPath(scene, i)).points;
    const std::vector<Point> source = io::readXyz(scanPath(scene, j)).points;
    const Pose guess = odometry.at(i).pose.inverse() * odometry.at(j).pose;
    std::vector<double> downsample, target_seconds, icp, total, cpu;
    PairRun first;
    for (int r = 0; r < runs; ++r) {
      PairRun run = registerPair(source, target, guess, config);
      downsample.push_back(run.times.downsample);
      target_seconds.push_back(run.times.target);
      icp.push_back(run.times.icp);
      total.push_back(run.times.total());
      cpu.push_back(run.times.cpu);
      if (r == 0) first = std::move(run);
    }
    const IcpResult& result = first.result;
    out["pairs"].push_back({{"target", i},
                            {"source", j},
                            {"points", {{"source", source.size()},
                                        {"target", target.size()},
                                        {"source_down", result.source_points},
                                        {"target_down", first.target_points}}},
                            {"matrix", matrixJson(result.pose)},
                            {"iterations", result.iterations},
                            {"inliers", result.inliers},
                            {"rms_residual", result.rms_residual},
                            {"converged", result.converged},
                            {"degenerate", result.degenerate},
                            {"seconds", {{"downsample", median(downsample)},
                                         {"target", median(target_seconds)},
                                         {"icp", median(icp)},
                                         {"total", median(total)},
                                         {"cpu", median(cpu)}}}});
    std::fprintf(stderr, "pair %zu-%zu: %.3f s, %d iterations\n", i, j, median(total), result.iterations);
  }
  std::printf("%s\n", out.dump(1).c_str());
  return 0;
}

}  // namespace mlmap::bench
