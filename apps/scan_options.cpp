#include "scan_options.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <optional>

#include "mlmap/error.hpp"
#include "mlmap/registration/up_axis.hpp"
#include "number_options.hpp"

namespace mlmap::cli {
namespace {

io::ScanInput inputOf(const ScanOptions& options) {
  io::ScanInput input;
  input.files.assign(options.scans.begin(), options.scans.end());
  input.poses = options.poses;
  input.identity = options.identity;
  input.range = options.range;
  input.scale = options.units == "mm" ? 0.001 : options.units == "cm" ? 0.01 : 1.0;
  input.isolated = options.isolated;
  return input;
}

std::optional<Eigen::Vector3d> namedAxis(const std::string& name) {
  const bool minus = !name.empty() && name[0] == '-';
  const std::string axis = name.substr(minus || (!name.empty() && name[0] == '+') ? 1 : 0);
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  if (axis == "x") up.x() = 1.0;
  else if (axis == "y") up.y() = 1.0;
  else if (axis == "z") up.z() = 1.0;
  else return std::nullopt;
  return minus ? Eigen::Vector3d(-up) : up;
}

const char* cueName(registration::UpCue cue) {
  switch (cue) {
    case registration::UpCue::Poses: return "the axis the scans turn about";
    case registration::UpCue::Positions: return "the plane the sensors moved in";
    case registration::UpCue::Image: return "the down of a depth camera's image (an organized PCD)";
    case registration::UpCue::Planes: return "the planes most surfaces face";
    case registration::UpCue::None: break;
  }
  return "no evidence";
}

}  // namespace

void addScanOptions(CLI::App* command, ScanOptions& options, const ScanOptionSet& set) {
  command->add_option("--poses", options.poses, set.poses_help);
  if (set.identity) {
    command->add_flag("--identity", options.identity,
                      "Map scans that carry no pose (XYZ, PLY, PCD without VIEWPOINT) at the origin when no --poses "
                      "is given (else that is an error)");
  }
  addNumber(command, "--min-range", options.range.min,
            "Drop readings nearer than this to the scanner, m (its own housing; 3DTK's scans)", 0.0,
            Bound::Closed)
      ->capture_default_str();
  addNumber(command, "--max-range", options.range.max,
            "Drop readings farther than this from the scanner, m (no-return readings: 3DTK's at 32.76 m)", 0.0,
            Bound::Open)
      ->capture_default_str();
  command->add_option("--mount", options.mount,
                      "Tilt correction (the JSON `mlmap calibrate` writes) applied to every scan");
  command->add_option("--up", options.up,
                      "The data's up axis, turned to +z before mapping: x y z -x -y -z, or auto to detect it "
                      "(default: z, with a warning when the data look otherwise)")
      ->check(CLI::IsMember({"x", "y", "z", "-x", "-y", "-z", "+x", "+y", "+z", "auto"}));
  command->add_option("--units", options.units,
                      "Units of the scans' coordinates and the pose file's positions: m, cm or mm (default m; 3DTK's "
                      ".3d files are converted from their centimetres as they are read: leave m for them)")
      ->check(CLI::IsMember({"m", "cm", "mm"}));
  command->add_flag("--level", options.level,
                    "Turn the data so that their level surfaces (floors, ceilings, found in the first file) face +z "
                    "exactly, after --up's turn: a scanner standing a few degrees off level, whose walls otherwise "
                    "lean across the map's cell rows and come apart; give label the same (default: off, with a "
                    "warning over 2 deg)");
  command->add_option("scans", options.scans, "Scan files: .xyz .txt .pts .dat .ply .pcd .3d (3DTK) .graph (OctoMap)")
      ->required();
}

ScanReading::ScanReading(const ScanOptions& options, const char* command, bool quiet)
    : sequence_(inputOf(options)), command_(command), quiet_(quiet) {
  if (!options.mount.empty()) mount_ = registration::readMountCorrection(options.mount);
  resolveUp(options.up, options.level);
}

std::vector<Scan> ScanReading::firstScans(Eigen::Vector3d* shift) const {
  std::vector<Scan> first;
  read([&](Scan& scan, std::size_t, std::size_t) { first.push_back(std::move(scan)); }, {}, 1);
  // Up and tilt are directions: judged near the origin, where the voxel keys that find the
  // planar cells reach (a national grid's coordinates lie beyond them, and a cloud there read
  // as y-up). As far as the map would be moved (chooseOrigin at 5 cm voxels).
  const Eigen::Vector3d moved = first.empty() ? Eigen::Vector3d::Zero() : chooseOrigin(first.front(), keyReach(0.05));
  for (Scan& scan : first) scan.pose.pretranslate(-moved);
  if (shift != nullptr) *shift = moved;
  return first;
}

// A wall of a storey (2.5 m) leaning 2 deg moves 8.7 cm across: more than a cell of 5 cm, so its
// blocks change cell rows on the way up and the wall comes apart. The simulated lab pitched
// 3 deg and rolled 1 deg (`bench/planes_sweep.py --conditions tilt3,tilt3level`): patch F1
// 0.83 at 5 cm cells, 0.96 levelled (1.5 and 0.5 deg: 0.91, 0.96). The real scans of
// ../shared/data lean 0.3-2.2 deg; levelled, the twelve grid placements of
// `bench/real_seeds.py --placements` find as many of their marked surfaces (581 / 636 against
// 582 / 636 of 768): their own warps weigh more than a lean under 2 deg.
constexpr double kWarnTiltDeg = 2.0;

void ScanReading::levelSurfaces(const std::vector<Scan>& first, bool level) {
  const std::optional<Eigen::Vector3d> normal = registration::levelNormal(first, Eigen::Vector3d::UnitZ());
  if (!normal) {
    if (level) std::fprintf(stderr, "mlmap: warning: --level: too few level planar surfaces in the first file to level by\n");
    return;
  }
  const double tilt_deg = std::acos(std::clamp(normal->z(), -1.0, 1.0)) * 180.0 / std::numbers::pi;
  if (!level) {
    if (tilt_deg > kWarnTiltDeg) {
      std::fprintf(stderr,
                   "mlmap: warning: the data's level surfaces lean %.1f deg off z: walls cross the map's cell rows and "
                   "come apart; give --level to level them\n",
                   tilt_deg);
    }
    return;
  }
  if (!quiet_) std::fprintf(stderr, "%s: levelled: the level surfaces leaned %.2f deg off z\n", command_.c_str(), tilt_deg);
  io::ScanInput input = sequence_.input();
  input.world = Pose(registration::rotationToLevel(*normal)) * input.world;
  sequence_ = io::ScanSequence(input);
}

void ScanReading::resolveUp(const std::string& up, bool level) {
  io::ScanInput input = sequence_.input();
  if (up == "z" || up == "+z") {
    if (level) levelSurfaces(firstScans(), true);
    return;
  }
  if (const auto axis = namedAxis(up)) {
    input.world = Pose(registration::rotationToZUp(*axis));
    sequence_ = io::ScanSequence(input);
    levelSurfaces(firstScans(), level);
    return;
  }
  // auto, or the default: look at the first file, and at every pose of a pose file (the
  // turns of a sequence of one-scan files: the first file alone has none, and one tilting-laser
  // scan of a narrow room faces its long walls more than its floor).
  Eigen::Vector3d shift;
  std::vector<Scan> first = firstScans(&shift);
  std::vector<Pose> poses;
  for (const io::StampedPose& stamped : sequence_.poses())
    poses.push_back(Eigen::Translation3d(-shift) * input.world * stamped.pose);
  const registration::UpAxisEstimate estimate = registration::estimateUpAxis(first, {}, poses);
  const bool z_up = estimate.up.z() > 0.5;
  const std::string evidence =
      estimate.faces_no_axis
          ? "the " + std::to_string(estimate.planar_cells) +
                " planar cells face no coordinate axis: the data look tilted (level a tilted sensor with "
                "`mlmap calibrate` and --mount)"
      : estimate.line_from == registration::UpCue::None
          ? std::string("too few planar surfaces and no turn to tell")
          : std::string("from ") + cueName(estimate.line_from) + ": " +
                std::to_string(static_cast<int>(100.0 * estimate.planar_share + 0.5)) +
                " % of the planar cells face it, " +
                std::to_string(static_cast<int>(100.0 * estimate.below_share + 0.5)) +
                " % of their points below the sensor";
  if (up == "auto") {
    if (!quiet_) {
      std::fprintf(stderr, "%s: up is %s (%s)%s\n", command_.c_str(), registration::axisName(estimate.up),
                   evidence.c_str(), z_up ? "" : ", turned to +z");
    }
    if (!z_up) {
      input.world = Pose(registration::rotationToZUp(estimate.up));
      sequence_ = io::ScanSequence(input);
      // The first file as read now, without reading it again (the sequence puts the world's
      // turn before each scan's pose).
      for (Scan& scan : first) scan.pose = input.world * scan.pose;
    }
    if (level) levelSurfaces(first, true);
    return;
  }
  // Warned only on strong evidence that the line differs from z: the scans turn about
  // another axis, a depth camera's image has its down along it, or half the planar cells
  // face it and its points lie on both sides of the sensor. A cloud registered by others
  // (PCD VIEWPOINT at an arbitrary origin: PCL's room scans, Bobkov's room, the stair scans)
  // gives no sign evidence and split families (44-51 % of the planar cells), and a camera's
  // single view (office1) shows the far wall as much as the floor: the planes alone would
  // warn wrongly there.
  const bool strong = estimate.line_from == registration::UpCue::Poses ||
                      estimate.line_from == registration::UpCue::Positions ||
                      estimate.line_from == registration::UpCue::Image ||
                      (estimate.line_from == registration::UpCue::Planes && estimate.planar_share >= 0.5 &&
                       estimate.below_share >= 0.1 && estimate.below_share <= 0.9);
  if (estimate.faces_no_axis) {
    std::fprintf(stderr, "mlmap: warning: %s; up is kept as z, which the planes' classes read\n", evidence.c_str());
    if (level) levelSurfaces(first, true);
    return;
  }
  // Up stays z: level about it, or say how far its level surfaces lean.
  if (std::abs(estimate.up.z()) > 0.5 || level) levelSurfaces(first, level);
  if (std::abs(estimate.up.z()) < 0.5 && strong) {
    // "--up y", not "--up +y": the option's own spelling.
    const char* name = registration::axisName(estimate.up);
    const char* option = name[0] == '+' ? name + 1 : name;
    std::fprintf(stderr,
                 "mlmap: warning: the data look %s-up, not z-up (%s); give --up %s or --up auto to turn "
                 "them, --up z to keep z\n",
                 option, evidence.c_str(), option);
  }
}

io::ScanInputCounts ScanReading::read(const io::ScanSequence::Visit& visit,
                                      const std::function<void(std::size_t file)>& file_done,
                                      std::size_t max_files) const {
  if (!mount_) return sequence_.forEach(visit, file_done, max_files);
  return sequence_.forEach(
      [&](Scan& scan, std::size_t index, std::size_t file) {
        registration::applyMountCorrection(scan, *mount_);
        visit(scan, index, file);
      },
      file_done, max_files);
}

io::ScanInputCounts ScanReading::forEach(const io::ScanSequence::Visit& visit,
                                         const std::function<void(std::size_t file)>& file_done) const {
  const io::ScanInputCounts counts = read(visit, file_done, static_cast<std::size_t>(-1));
  if (!quiet_ && counts.too_near + counts.too_far > 0) {
    const io::RangeLimits& range = sequence_.input().range;
    std::fprintf(stderr, "%s: dropped %zu readings nearer than %g m and %zu beyond %g m (--min-range, --max-range)\n",
                 command_.c_str(), counts.too_near, range.min, counts.too_far, range.max);
    // A scanner's own and no-return readings are a few percent of a scan (3DTK's: ~5 %).
    if (counts.too_near + counts.too_far > counts.points)
      std::fprintf(stderr, "%s: that is most of them; the limits are distances from the scanner, and a scan without a "
                           "pose is seen from its frame's origin: a cloud registered in another frame needs "
                           "--min-range 0 and a --max-range beyond its extent\n", command_.c_str());
  }
  if (!quiet_ && counts.isolated > 0) {
    const io::IsolationFilter& filter = sequence_.input().isolated;
    std::fprintf(stderr, "%s: dropped %zu isolated readings (%.2f %%: fewer than %d others within %g m, --outlier-radius)\n",
                 command_.c_str(), counts.isolated,
                 100.0 * static_cast<double>(counts.isolated) / static_cast<double>(counts.points + counts.isolated),
                 filter.min_neighbours, filter.radius);
  }
  return counts;
}

ScanReading ScanReading::withPoses(std::vector<io::StampedPose> poses) const {
  ScanReading copy = *this;
  copy.sequence_ = sequence_.withPoses(std::move(poses));
  return copy;
}

}  // namespace mlmap::cli
