// Scans read for mapping: files in order, each scan paired with its pose (pose i of a
// TUM file, else the one its file carries), its readings limited to the ranges a
// scanner measures, optionally turned into another world frame (e.g. z up). The CLI's
// build, label and register read their inputs this way, and so can any program.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <vector>

#include "mlmap/io/isolated_points.hpp"
#include "mlmap/io/tum_poses.hpp"
#include "mlmap/scan.hpp"

namespace mlmap::io {

// Readings outside [min, max] of the scan's sensor origin are dropped: a scanner's
// no-return readings and the ones off its own housing. The defaults are measured on two
// data sets the project did not record:
//  - 3DTK's dat/ scans (3 × 81,360 readings): the 2,147 / 2,003 / 2,004 readings under
//    0.40 m all lie in the scanner's own scan plane beside it (|x|, |z| < 0.1 m), the
//    floor's first readings come at 0.40-0.45 m; the no-return readings sit at
//    32.76-32.77 m (1,481 / 1,313 / 1,618 per scan), and 19 / 1 / 96 more lie beyond 30 m
//    in a building of 13 x 10 m. (3DTK's own dat/config.ini keeps 0.48-32.76 m.)
//  - OctoMap's scan.dat (88,206 readings): nearest 0.467 m, farthest 29.05 m; all kept.
// 30 m is also the rated range of the paper's scanner, the UTM-30LX.
struct RangeLimits {
  double min = 0.4;   // m
  double max = 30.0;  // m

  bool contains(const Point& sensor_point) const {
    const double squared = sensor_point.squaredNorm();
    return squared >= min * min && squared <= max * max;
  }
};

// Drops the scan's readings outside the limits, with their variances and labels.
// Returns how many it dropped.
std::size_t applyRangeLimits(Scan& scan, const RangeLimits& limits);

// Throws an Error naming the file and the scan's number in the sequence (`index`, from 0;
// a .graph file holds several) when the scan holds readings but none within the limits:
// a cloud registered in another frame and read without a pose (--identity) is "seen"
// from that frame's origin, which may lie tens of metres away or inside the room, and
// the map of it would be empty.
void requireReadingsInRange(const Scan& scan, const RangeLimits& limits, const std::filesystem::path& file,
                            std::size_t index);

struct ScanInput {
  std::vector<std::filesystem::path> files{};  // in order; a .graph holds several scans
  std::filesystem::path poses{};             // TUM, pose i for scan i; empty: each scan's own
  // A scan whose file carries no pose (XYZ, PLY, a PCD without VIEWPOINT) and no pose file:
  // an error, unless this says such scans sit at the world's origin. Silently mapping
  // every scan of a sequence at one pose gives a map of nothing.
  bool identity = false;
  RangeLimits range{};
  IsolationFilter isolated{};      // off by default; applied after the range limits
  Pose world = Pose::Identity();  // applied after each scan's pose (e.g. turns the data z-up)
  // m per unit of the files' coordinates and of the pose file's positions (0.001 for
  // millimetres), applied as each scan is read, before the range limits
  double scale = 1.0;
};

struct ScanInputCounts {
  std::size_t scans = 0;
  std::size_t points = 0;     // kept
  std::size_t too_near = 0;   // dropped, under range.min
  std::size_t too_far = 0;    // dropped, beyond range.max
  std::size_t isolated = 0;   // dropped by the isolation filter
};

class ScanSequence {
 public:
  // Checks what can be checked before any scan is read, so a long run does not fail at
  // its end: every file's format, the pose file, its count against the files' (when
  // each holds one scan), and the pose rule for formats that never carry a pose.
  // Throws mlmap::Error naming the file.
  explicit ScanSequence(ScanInput input);

  const ScanInput& input() const { return input_; }
  const std::vector<StampedPose>& poses() const { return poses_; }  // the pose file's; empty without one

  using Visit = std::function<void(Scan& scan, std::size_t index, std::size_t file)>;
  // Reads one file at a time (memory holds the work, not every scan) and calls
  // visit(scan, index, file) for every scan, in the sensor frame with its world pose
  // set, then file_done(file) after each file. Throws mlmap::Error naming the pose file
  // when it holds fewer or more poses than there are scans.
  // With max_files, only that many files are read (and the pose count is not checked).
  ScanInputCounts forEach(const Visit& visit, const std::function<void(std::size_t file)>& file_done = {},
                          std::size_t max_files = static_cast<std::size_t>(-1)) const;

  // The same scans with these world poses instead (one per scan, in order; e.g. corrected
  // by registration): input().world is not applied again.
  ScanSequence withPoses(std::vector<StampedPose> poses) const;

 private:
  ScanInput input_;
  std::vector<StampedPose> poses_;
};

}  // namespace mlmap::io
