#include "mlmap/io/scan_input.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "mlmap/error.hpp"
#include "kept_readings.hpp"
#include "mlmap/io/scan_file.hpp"

namespace mlmap::io {
namespace {

std::string noPoseMessage(const std::filesystem::path& file) {
  return file.string() + ": the scan carries no pose; give --poses, or --identity to map it at the origin";
}

}  // namespace

std::size_t applyRangeLimits(Scan& scan, const RangeLimits& limits) {
  return keepReadings(scan, [&](std::size_t k) { return limits.contains(scan.points[k]); });
}

void requireReadingsInRange(const Scan& scan, const RangeLimits& limits, const std::filesystem::path& file,
                            std::size_t index) {
  double nearest = std::numeric_limits<double>::infinity();
  double farthest = 0.0;
  std::vector<double> ranges;
  for (const Point& point : scan.points) {
    if (limits.contains(point)) return;
    const double range = point.norm();
    if (!std::isfinite(range)) continue;
    nearest = std::min(nearest, range);
    farthest = std::max(farthest, range);
    ranges.push_back(range);
  }
  if (!(farthest >= nearest)) return;  // no finite readings: the reader's to judge
  char text[320];
  std::snprintf(text, sizeof text,
                ": none of its %zu readings lies within %g-%g m of the scanner (they lie %.4g-%.4g m from it); a "
                "cloud registered in another frame, read without a pose, needs --min-range 0 --max-range %.4g",
                scan.size(), limits.min, limits.max, nearest, farthest, std::ceil(farthest + 1.0));
  // A cloud in millimetres or centimetres puts a room's readings 1,000 or 100 times too far:
  // its median reading would lie within the limits (a scanner's junk aside) and over a metre.
  std::string units;
  const auto middle = ranges.begin() + static_cast<std::ptrdiff_t>(ranges.size() / 2);
  std::nth_element(ranges.begin(), middle, ranges.end());
  const double median = *middle;
  for (const auto& [name, scale] : {std::pair{"mm", 0.001}, std::pair{"cm", 0.01}}) {
    if (units.empty() && limits.contains(Point(median * scale, 0.0, 0.0)) && median * scale > 1.0)
      units = std::string("; or, if its coordinates are ") + (scale == 0.001 ? "millimetres" : "centimetres") +
              ", --units " + name;
  }
  throw Error(file.string() + " (scan " + std::to_string(index + 1) + ")" + text + units);
}

ScanSequence::ScanSequence(ScanInput input) : input_(std::move(input)) {
  const RangeLimits& range = input_.range;
  if (!(range.min >= 0.0) || !(range.max > range.min)) {
    throw Error("range limits: need 0 <= minimum < maximum, got " + std::to_string(range.min) + " and " +
                std::to_string(range.max) + " m");
  }
  if (input_.files.empty()) throw Error("no scan files");
  bool counted = true;  // every file holds one scan
  for (const std::filesystem::path& file : input_.files) {
    const ScanFileKind kind = scanFileKind(file);
    counted = counted && kind.single_scan;
    if (input_.poses.empty() && !input_.identity && !kind.carries_pose) throw Error(noPoseMessage(file));
  }
  if (input_.poses.empty()) return;
  poses_ = readTumPoses(input_.poses);
  if (counted && poses_.size() != input_.files.size()) {
    throw Error(input_.poses.string() + ": " + std::to_string(poses_.size()) + " poses for " +
                std::to_string(input_.files.size()) + " scans");
  }
}

ScanSequence ScanSequence::withPoses(std::vector<StampedPose> poses) const {
  ScanSequence copy = *this;
  copy.poses_ = std::move(poses);
  copy.input_.world = Pose::Identity();
  copy.input_.poses = copy.input_.poses.empty() ? std::filesystem::path("the corrected poses") : copy.input_.poses;
  return copy;
}

ScanInputCounts ScanSequence::forEach(const Visit& visit, const std::function<void(std::size_t file)>& file_done,
                                      std::size_t max_files) const {
  ScanInputCounts counts;
  const double min_squared = input_.range.min * input_.range.min;
  const std::size_t files = std::min(max_files, input_.files.size());
  for (std::size_t file = 0; file < files; ++file) {
    for (Scan& scan : readScans(input_.files[file])) {
      const std::size_t index = counts.scans;
      if (!poses_.empty()) {
        if (index >= poses_.size()) {
          throw Error(input_.poses.string() + ": " + std::to_string(poses_.size()) +
                      " poses, but there are more scans (" + input_.files[file].string() + " is scan " +
                      std::to_string(index + 1) + ")");
        }
        scan.pose = poses_[index].pose;
      }
      if (input_.scale != 1.0) {
        for (Point& point : scan.points) point *= input_.scale;
        scan.pose.translation() *= input_.scale;
      }
      std::size_t outside = 0;
      for (const Point& point : scan.points) {
        if (input_.range.contains(point)) continue;
        ++outside;
        ++(point.squaredNorm() < min_squared ? counts.too_near : counts.too_far);
      }
      if (outside == scan.size()) requireReadingsInRange(scan, input_.range, input_.files[file], index);
      applyRangeLimits(scan, input_.range);
      counts.isolated += dropIsolated(scan, input_.isolated);
      scan.pose = input_.world * scan.pose;
      counts.points += scan.size();
      ++counts.scans;
      visit(scan, index, file);
    }
    if (file_done) file_done(file);
  }
  if (files == input_.files.size() && !poses_.empty() && counts.scans != poses_.size()) {
    throw Error(input_.poses.string() + ": " + std::to_string(poses_.size()) + " poses for " +
                std::to_string(counts.scans) + " scans");
  }
  return counts;
}

}  // namespace mlmap::io
