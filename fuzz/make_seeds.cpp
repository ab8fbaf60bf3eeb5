// Writes the seed corpora under fuzz/corpus/<target>/: small files made by the
// project's own writers (as the round-trip tests make them), the hand-written variants
// the parser tests feed in, device replies built from the SCIP and PTU protocol rules
// as tests/test_scip.cpp and tests/test_ptu.cpp queue them, and a raw log recorded from
// the emulator. Run by scripts/fuzz.sh --seeds; the output is committed.
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "mlmap/driver/acquisition.hpp"
#include "mlmap/driver/emulator.hpp"
#include "mlmap/driver/raw_log.hpp"
#include "mlmap/driver/scip.hpp"
#include "mlmap/io/map_file.hpp"
#include "mlmap/io/pcd.hpp"
#include "mlmap/io/planes_json.hpp"
#include "mlmap/io/ply.hpp"
#include "mlmap/io/scan_graph.hpp"
#include "mlmap/io/threedtk.hpp"
#include "mlmap/io/tum_poses.hpp"
#include "mlmap/io/xyz.hpp"
#include "mlmap/planes/ermsm.hpp"
#include "mlmap/sim/scene.hpp"

namespace fs = std::filesystem;
using namespace mlmap;

namespace {

std::string readAll(const fs::path& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  std::string bytes;
  char buffer[4096];
  std::size_t got = 0;
  while ((got = std::fread(buffer, 1, sizeof(buffer), file)) > 0) bytes.append(buffer, got);
  std::fclose(file);
  return bytes;
}

class Corpus {
 public:
  explicit Corpus(fs::path root) : root_(std::move(root)) {}
  void add(const std::string& target, const std::string& name, const std::string& bytes) const {
    fs::create_directories(root_ / target);
    std::FILE* file = std::fopen((root_ / target / name).c_str(), "wb");
    std::fwrite(bytes.data(), 1, bytes.size(), file);
    std::fclose(file);
  }
  // What `write` puts into a scratch file named `name`.
  template <typename Write>
  std::string made(const std::string& name, Write&& write) const {
    const fs::path path = root_ / ".scratch" / name;
    fs::create_directories(path.parent_path());
    write(path);
    return readAll(path);
  }
  void clearScratch() const { fs::remove_all(root_ / ".scratch"); }
  const fs::path& root() const { return root_; }

 private:
  fs::path root_;
};

Scan smallScan(std::size_t count, bool labels, std::uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> coordinate(-5.0, 5.0);
  Scan scan;
  for (std::size_t i = 0; i < count; ++i) {
    scan.points.emplace_back(coordinate(random), coordinate(random), coordinate(random) * 0.3);
    if (labels) scan.labels.push_back(static_cast<std::int32_t>(i % 3) - 1);
  }
  scan.pose.translation() = Eigen::Vector3d(1.0, -2.0, 0.5);
  scan.pose.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return scan;
}

void fileSeeds(const Corpus& corpus) {
  const Scan plain = smallScan(6, false, 1);
  const Scan labelled = smallScan(6, true, 2);

  corpus.add("xyz", "plain", corpus.made("a.xyz", [&](auto& p) { io::writeXyz(p, plain); }));
  corpus.add("xyz", "labelled", corpus.made("a.xyz", [&](auto& p) { io::writeXyz(p, labelled); }));
  corpus.add("xyz", "intensity", "# x y z intensity\n1.5 2 -3e-2 0.53\n+4,5,6 1.0\r\n\n7\t8\t9 0.1 # c\n");

  corpus.add("ply", "ascii", corpus.made("a.ply", [&](auto& p) { io::writePly(p, labelled, io::PlyEncoding::Ascii); }));
  corpus.add("ply", "binary", corpus.made("a.ply", [&](auto& p) { io::writePly(p, plain); }));
  corpus.add("ply", "binary_labelled", corpus.made("a.ply", [&](auto& p) { io::writePly(p, labelled); }));
  corpus.add("ply", "faces_first",
             "ply\nformat ascii 1.0\ncomment faces before the vertices\nelement face 1\n"
             "property list uchar int vertex_indices\nelement vertex 2\nproperty double x\n"
             "property double y\nproperty double z\nproperty uchar red\nproperty list uchar float n\n"
             "end_header\n3 0 1 1\n1 2 3 255 2 0.5 0.5\n4 5 6 0 0\n");

  corpus.add("pcd", "ascii", corpus.made("a.pcd", [&](auto& p) { io::writePcd(p, labelled, io::PcdEncoding::Ascii); }));
  corpus.add("pcd", "binary", corpus.made("a.pcd", [&](auto& p) { io::writePcd(p, labelled, io::PcdEncoding::Binary); }));
  corpus.add("pcd", "compressed", corpus.made("a.pcd", [&](auto& p) { io::writePcd(p, plain, io::PcdEncoding::BinaryCompressed); }));
  corpus.add("pcd", "compressed_labelled",
             corpus.made("a.pcd", [&](auto& p) { io::writePcd(p, labelled, io::PcdEncoding::BinaryCompressed); }));
  corpus.add("pcd", "organized_nan",
             "VERSION .7\nFIELDS x y z rgb normal\nSIZE 4 4 8 4 4\nTYPE F F F U F\nCOUNT 1 1 1 1 3\n"
             "WIDTH 2\nHEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4\nDATA ascii\n1 2 3 7 0 0 1\n"
             "nan nan nan 0 0 0 0\n4 5 6 1 0 1 0\n-1 -2 -3e2 9 1 0 0\n");

  const std::string three_d = corpus.made("scan000.3d", [&](auto& p) { io::writeThreeDtkScan(p, plain); });
  const std::string pose = readAll(corpus.root() / ".scratch" / "scan000.pose");
  corpus.add("threedtk", "written", three_d + std::string(1, '\0') + pose);
  corpus.add("threedtk", "old_header", "360 x 225\n100 20 300 0.7\n-4 5 6\n" + std::string(1, '\0') +
                                           "10 20 30\n0 90 -45\n");

  std::vector<io::StampedPose> poses(3);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    poses[i].stamp = 1.5 * static_cast<double>(i);
    poses[i].pose = smallScan(1, false, static_cast<std::uint32_t>(i)).pose;
  }
  corpus.add("tum", "written", corpus.made("poses.txt", [&](auto& p) { io::writeTumPoses(p, poses); }));
  corpus.add("tum", "comments", "# stamp tx ty tz qx qy qz qw\n0 1 2 3 0 0 0 1\n\n1.5 1 2 3 0 0 0.7071 0.7071 # c\n");

  corpus.add("graph", "binary", corpus.made("a.graph", [&](auto& p) {
    io::writeScanGraph(p, {smallScan(3, false, 3), smallScan(2, false, 4)});
  }));
  corpus.add("graph", "ascii", "# plain ASCII log\nNODE 1 2 0.5 0 0 1.57\n1 0 0\n2 0 0\nNODE 0 0 0 0 0 0\n0 1 2\n");

  const auto addMap = [&](const std::string& name, const Map& map) {
    std::string bytes = corpus.made("a.mlmap", [&](auto& p) { io::writeMap(p, map); });
    bytes.resize(bytes.size() - 4);  // the fuzz target appends the checksum
    corpus.add("mlmap", name, bytes);
  };
  for (const bool octree : {false, true}) {
    MapConfig config;
    config.cell_size = 0.5;
    config.with_octree = octree;
    Map map(config);
    map.insertScan(smallScan(12, false, 5));
    addMap(octree ? "with_octree" : "blocks_only", map);
  }

  // A labelled map and its planes export: a 1.5 m floor and a wall, in 10 cm cells.
  MapConfig config;
  config.cell_size = 0.1;
  config.with_octree = false;
  Map room(config);
  Scan surfaces;
  for (int i = 0; i < 15; ++i) {
    for (int j = 0; j < 15; ++j) {
      surfaces.points.emplace_back(0.05 + 0.1 * i, 0.05 + 0.1 * j, 0.0);
      surfaces.points.emplace_back(0.05 + 0.1 * i, 0.02, 0.05 + 0.1 * j);
    }
  }
  room.insertIntoBlocks(surfaces);
  PlaneDetection detection = detectPlanes(room.blocks());
  corpus.add("planes_json", "room", io::planesJson(room, detection, "room.mlmap"));
  room.setPlanes(std::move(detection));
  addMap("with_planes", room);
}

// ---------------------------------------------------------------- device replies

std::string frame(const std::string& echo, const std::string& status, const std::string& body = "") {
  return echo + "\n" + driver::scipLine(status) + body + "\n";
}

std::string keyValues(const std::vector<std::pair<std::string, std::string>>& pairs) {
  std::string body;
  for (const auto& [key, value] : pairs) body += driver::scipLine(key + ":" + value + ";");
  return body;
}

// Timestamp line, then the values in 64-character lines.
std::string scanBody(std::uint32_t stamp, std::size_t count, int width) {
  std::string data;
  for (std::size_t i = 0; i < count; ++i) {
    data += driver::scipEncode(static_cast<std::uint32_t>(400 + 53 * i) % (1u << (6 * width)), width);
  }
  std::string body = driver::scipLine(driver::scipEncode(stamp, 4));
  for (std::size_t at = 0; at < data.size(); at += 64) body += driver::scipLine(data.substr(at, 64));
  return body;
}

void scipSeeds(const Corpus& corpus) {
  const auto seed = [&](const std::string& target, const std::string& name, char selector,
                        const std::string& bytes) { corpus.add(target, name, std::string(1, selector) + bytes); };
  seed("scip_reply", "vv", 0, frame("VV", "00", keyValues({{"VEND", "Hokuyo Automatic Co.,Ltd."},
                                                           {"PROD", "SOKUIKI Sensor UTM-30LX"},
                                                           {"FIRM", "1.1.0"},
                                                           {"PROT", "SCIP 2.0"},
                                                           {"SERI", "H0000000"}})));
  seed("scip_reply", "pp", 1, frame("PP", "00", keyValues({{"MODL", "UTM-30LX"},
                                                           {"DMIN", "23"},
                                                           {"DMAX", "60000"},
                                                           {"ARES", "1440"},
                                                           {"AMIN", "0"},
                                                           {"AMAX", "1080"},
                                                           {"AFRT", "540"},
                                                           {"SCAN", "2400"}})));
  seed("scip_reply", "ii", 2, frame("II", "00", keyValues({{"MODL", "UTM-30LX"},
                                                           {"LASR", "OFF"},
                                                           {"SCSP", "2400"},
                                                           {"TIME", "0012ab"}})));
  seed("scip_reply", "bm", 3, frame("BM", "00"));
  seed("scip_reply", "bm_already_on", 3, frame("BM", "02"));
  seed("scip_reply", "qt", 4, "stale\nlines\n" + frame("QT", "00"));
  seed("scip_reply", "rs", 5, frame("RS", "00"));
  std::string tm = frame("TM0", "00");
  for (std::uint32_t stamp : {1000u, 1012u, 16777210u}) {
    tm += frame("TM1", "00", driver::scipLine(driver::scipEncode(stamp, 4)));
  }
  seed("scip_reply", "tm", 6, tm + frame("TM2", "00"));
  seed("scip_reply", "gd", 7, frame("GD0000004301", "00", scanBody(4242, 44, 3)));
  seed("scip_reply", "gs", 8, frame("GS0010010903", "00", scanBody(77, 34, 2)));

  for (int selector = 0; selector < 4; ++selector) {
    const bool three = (selector & 1) == 0;
    const int cluster = (selector & 2) ? 4 : 1;
    const int width = three ? 3 : 2;
    const std::string command = std::string(three ? "MD" : "MS") + "00000099" +
                                (cluster == 4 ? "04" : "01") + "0";
    std::string stream = frame(command + "00", "00");
    const std::size_t count = 99 / static_cast<std::size_t>(cluster) + 1;
    for (std::uint32_t k = 0; k < 3; ++k) {
      stream += frame(command + "00", "99", scanBody(16777150u + 25 * k, count, width));
    }
    seed("scip_stream", std::string(three ? "md" : "ms") + "_cluster" + std::to_string(cluster),
         static_cast<char>(selector), stream);
  }
}

void ptuSeeds(const Corpus& corpus) {
  const auto seed = [&](const std::string& name, char selector, const std::string& bytes) {
    corpus.add("ptu", name, std::string(1, selector) + bytes);
  };
  seed("initialise_terse", 0,
       "*\r\n*\r\n*\r\n* 185.1428\r\n* -3090\r\n* 3090\r\n* 185.1428\r\n* -907\r\n* 604\r\n*\r\n*\r\n");
  seed("initialise_verbose", 0,
       "ED *\r\n*\r\n*\r\n* 185.1428 seconds arc per position\r\n* Minimum Pan position is -3090\r\n"
       "* Maximum Pan position is 3090\r\n* 46.2857\r\n* -3600\r\n* 2000\r\n! Illegal position\r\n");
  seed("queries", 1, "* 100\r\n* Current Tilt speed is 1000\r\n* -2000\r\n");
  seed("await", 2, "*\r\n!T\r\n*\r\n");
  seed("limit", 3, "!P\r\n* 50\r\n");
}

// A short sweep against the emulator, recorded as `mlmap scan --log` records it.
void rawLogSeed(const Corpus& corpus) {
  const sim::Scene scene = sim::parseScene(R"({"name": "box", "poses": [{"x": 1, "y": 1}],
    "surfaces": [{"type": "box", "name": "room", "class": "wall", "min": [-1, -1, -1], "max": [3, 3, 2]}]})",
                                           "box.json");
  driver::EmulatorOptions emulator_options;
  emulator_options.time_scale = 4.0;
  driver::Emulator emulator(scene, emulator_options);
  const auto laser_device = driver::openDevice(emulator.laserPath());
  const auto ptu_device = driver::openDevice(emulator.ptuPath());
  driver::RawLog log;
  driver::RecordingTransport laser_transport(*laser_device, log, 'L');
  driver::RecordingTransport ptu_transport(*ptu_device, log, 'P');
  driver::SweepOptions options;
  options.tilt_start_deg = -3.0;
  options.tilt_end_deg = 3.0;
  options.rho_deg = 3.0;
  options.cluster = 99;
  options.time_samples = 2;
  log.metadata = driver::sweepToJson(options, Pose::Identity());
  driver::ScipClient laser(laser_transport, std::chrono::milliseconds(options.timeout_ms));
  driver::PtuClient ptu(ptu_transport, std::chrono::milliseconds(options.timeout_ms));
  driver::acquireScan(laser, ptu, options, Pose::Identity());
  corpus.add("rawlog", "sweep", corpus.made("sweep.log", [&](auto& p) { log.save(p); }));
  // The same devices' answers for the acquisition target: laser length, laser, PTU.
  std::string laser_bytes, ptu_bytes;
  for (const auto& record : log.records()) {
    if (record.direction == 'r') (record.device == 'L' ? laser_bytes : ptu_bytes) += record.bytes;
  }
  std::string both = {static_cast<char>(laser_bytes.size() & 0xFF), static_cast<char>(laser_bytes.size() >> 8)};
  corpus.add("acquisition", "sweep", both + laser_bytes + ptu_bytes);
}

}  // namespace

// The shipped scenes (boxes, a cylinder, includes and an opening; run from the repository's
// root, as scripts/fuzz.sh does) and a flight of stairs.
void sceneSeeds(const Corpus& corpus) {
  for (const char* name : {"lab", "corridor", "building_lab"}) {
    const fs::path path = fs::path("maps") / (std::string(name) + ".json");
    if (fs::exists(path)) corpus.add("scene", name, readAll(path));
  }
  corpus.add("scene", "stairs", R"({"name": "stairwell",
 "scan_pattern": {"field_of_view_deg": 270, "angular_step_deg": 0.25, "tilt_start_deg": -30, "tilt_end_deg": 40,
                  "tilt_step_deg": 0.5, "min_range": 0.023, "max_range": 30, "range_sigma": 0.01, "mount_height": 1.2, "seed": 3},
 "odometry": {"translation_noise_per_m": 0.0, "yaw_noise_per_rad": 0.0, "yaw_noise_per_m": 0.0, "seed": 7},
 "poses": [{"x": 3.0, "y": 2.0, "yaw_deg": 4}],
 "surfaces": [
  {"type": "rectangle", "name": "floor", "class": "floor", "min": [0, 0, 0], "max": [14, 4.5, 0]},
  {"type": "rectangle", "name": "wall", "class": "wall", "min": [0, 0, 0], "max": [0, 4.5, 5.0], "facing": "+x"},
  {"type": "stairs", "name": "flight", "start": [5.0, 0.6], "yaw_deg": 4, "width": 3.0, "steps": 13,
   "riser": 0.14, "tread": 0.30, "top_depth": 1.5}]}
)");
}

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s CORPUS_DIR\n", argv[0]);
    return 2;
  }
  const Corpus corpus(argv[1]);
  fileSeeds(corpus);
  scipSeeds(corpus);
  ptuSeeds(corpus);
  rawLogSeed(corpus);
  sceneSeeds(corpus);
  corpus.clearScratch();
  return 0;
}
