// mlmap_bench icp-starts JOBS.json [--plain]
//
// JOBS.json: {"pairs": [{"id": "...", "source": "scan_001.xyz", "target": "scan_000.xyz",
//              "starts": [[16 numbers, 4x4 row by row: source -> target], ...]}, ...]}
// Each pair is prepared once as `mlmap register` prepares a scan and its map (range crop,
// voxel down-sampling, the target's voxel hash and normals: SequenceConfig's defaults);
// then for each start, alignVerified (the wide basin, verification and retries), or with
// --plain one alignPoints run at `mlmap register`'s 0.5 m gate (the ICP before the basin).
// Time per run = the pair's preparation + that run's ICP (the peers time the same steps),
// file reading excluded. JSON on stdout; bench/icp_stress.py scores it.
#include "stopwatch.hpp"
#include "icp_starts.hpp"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mlmap/error.hpp"
#include "mlmap/io/xyz.hpp"
#include "mlmap/registration/preprocessing.hpp"
#include "mlmap/registration/sequence_registration.hpp"
#include "mlmap/registration/verified_icp.hpp"

namespace mlmap::bench {
namespace {

using namespace mlmap::registration;

Pose poseOf(const nlohmann::json& values, const std::string& where) {
  if (!values.is_array() || values.size() != 16) throw Error(where + ": a start must be 16 numbers");
  Pose pose = Pose::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) pose.matrix()(r, c) = values.at(static_cast<std::size_t>(4 * r + c)).get<double>();
  }
  return pose;
}

nlohmann::json matrixJson(const Pose& pose) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) {
    rows.push_back({pose.matrix()(r, 0), pose.matrix()(r, 1), pose.matrix()(r, 2), pose.matrix()(r, 3)});
  }
  return rows;
}

}  // namespace

int runIcpStarts(int argc, char** argv) {
  std::string jobs_path;
  bool plain = false;
  for (int k = 1; k < argc; ++k) {
    if (std::strcmp(argv[k], "--plain") == 0) {
      plain = true;
    } else if (std::strcmp(argv[k], "--help") == 0) {
      std::printf("usage: mlmap_bench icp-starts JOBS.json [--plain]\n");
      return 0;
    } else {
      jobs_path = argv[k];
    }
  }
  std::ifstream file(jobs_path);
  if (!file) throw Error(jobs_path + ": cannot open");
  const nlohmann::json jobs = nlohmann::json::parse(file);
  const SequenceConfig config;
  nlohmann::json out;
  out["method"] = plain ? "mlmap alignPoints (0.5 m gate, no retries)" : "mlmap alignVerified";
  out["runs"] = nlohmann::json::array();
  for (const nlohmann::json& pair : jobs.at("pairs")) {
    const std::string id = pair.at("id").get<std::string>();
    const std::vector<Point> source_raw = io::readXyz(pair.at("source").get<std::string>()).points;
    const std::vector<Point> target_raw = io::readXyz(pair.at("target").get<std::string>()).points;
    const auto prep_start = Clock::now();
    const std::vector<Point> target_dense =
        voxelDownSample(target_raw, config.map_voxel_size / 2.0, config.min_range, config.max_range);
    const std::vector<Point> source =
        voxelDownSample(source_raw, config.source_voxel_size, config.min_range, config.max_range);
    VoxelHashMap map(config.map_voxel_size, config.max_points_per_voxel);
    map.addPoints(target_dense);
    map.estimateNormals(config.normals);
    const double prep_seconds = secondsSince(prep_start);
    std::size_t index = 0;
    for (const nlohmann::json& values : pair.at("starts")) {
      const Pose start = poseOf(values, id);
      const auto icp_start = Clock::now();
      nlohmann::json run = {{"id", id}, {"start", index++}};
      if (plain) {
        const IcpResult result = alignPoints(source, map, start, config.icp);
        run["matrix"] = matrixJson(result.pose);
        run["verified"] = !result.unreliable;
        run["attempts"] = 1;
      } else {
        const VerifiedIcp result = alignVerified(source, map, start, config.icp);
        run["matrix"] = matrixJson(result.icp.pose);
        run["verified"] = result.verified;
        run["attempts"] = result.attempts;
        run["explained"] = result.check.explained_share;
        run["spread"] = result.check.spread;
        run["noise"] = result.noise;
        run["first_matched"] = result.first_matched_share;
        run["eigenvalue_ratio"] = result.check.eigenvalue_ratio;
        run["rotation_ratio"] = result.check.rotation_ratio;
        run["unconstrained"] = result.unconstrained;
        run["no_overlap"] = result.no_overlap;
        run["ambiguous"] = result.ambiguous;
        run["rival_runs"] = result.rival_runs;
        run["rival_share"] = result.rival_share;
        run["slides"] = result.slides;
        run["slide_fit"] = result.slide_fit;
        const SlideProfile& profile = result.check.profile;
        run["profile"] = {{"facing", profile.facing}, {"at_result", profile.at_result}, {"away", profile.away},
                          {"best", profile.best}, {"best_shift", profile.best_shift}, {"peaked", profile.peaked}};
      }
      const double icp_seconds = secondsSince(icp_start);
      run["seconds"] = {{"prepare", prep_seconds}, {"icp", icp_seconds}, {"total", prep_seconds + icp_seconds}};
      out["runs"].push_back(run);
    }
  }
  std::printf("%s\n", out.dump(1).c_str());
  return 0;
}

}  // namespace mlmap::bench
