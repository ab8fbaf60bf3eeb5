// The options of every command that reads scans (build, label, register), in one place:
// the scan files, --poses / --identity, --min-range / --max-range, --mount and --up;
// and the reading they ask for, checked before the long work.
#pragma once

#include <CLI/CLI.hpp>

#include <optional>
#include <string>
#include <vector>

#include "mlmap/io/scan_input.hpp"
#include "mlmap/registration/floor_calibration.hpp"
#include "output_check.hpp"

namespace mlmap::cli {

struct ScanOptions {
  std::vector<std::string> scans;
  std::string poses;
  bool identity = false;
  io::RangeLimits range;
  io::IsolationFilter isolated;  // set by the commands that offer it (build)
  std::string mount;  // from `mlmap calibrate`
  std::string up;     // x y z -x -y -z auto; empty: z, with a warning when the data disagree
  bool level = false; // turn the level surfaces exactly to +z (after --up's turn)
  std::string units = "m";  // m cm mm: of the files' coordinates and the pose file's positions
};

struct ScanOptionSet {
  const char* poses_help;
  bool identity = true;  // register starts from identity when it has no poses: no flag
};

// Adds the options; the positional scans last (call it after the command's own positionals).
void addScanOptions(CLI::App* command, ScanOptions& options, const ScanOptionSet& set);

// The scans as the options say, with the mount correction applied and the world turned
// z-up as --up asks (and levelled as --level asks). The constructor checks the files, the
// pose file and the mount, and resolves --up and --level (reading the first file for auto,
// --level or to warn), printing on stderr what it decided.
class ScanReading {
 public:
  ScanReading(const ScanOptions& options, const char* command, bool quiet);

  const io::ScanSequence& sequence() const { return sequence_; }
  // As ScanSequence::forEach, each scan's mount corrected; prints the readings the range
  // limits dropped (unless quiet).
  io::ScanInputCounts forEach(const io::ScanSequence::Visit& visit,
                              const std::function<void(std::size_t file)>& file_done = {}) const;
  // The same reading with corrected world poses (see ScanSequence::withPoses).
  ScanReading withPoses(std::vector<io::StampedPose> poses) const;

 private:
  void resolveUp(const std::string& up, bool level);
  // The first file's scans, in the world frame as turned so far.
  // The first file's scans, moved near the origin where they lie far from it (`shift`: by how
  // much, the move subtracted).
  std::vector<Scan> firstScans(Eigen::Vector3d* shift = nullptr) const;
  // Turns the world so that the first file's level surfaces face +z exactly (--level), or
  // warns where they lean over kWarnTiltDeg and no --level was given.
  void levelSurfaces(const std::vector<Scan>& first, bool level);
  io::ScanInputCounts read(const io::ScanSequence::Visit& visit, const std::function<void(std::size_t file)>& file_done,
                           std::size_t max_files) const;

  io::ScanSequence sequence_;
  std::optional<registration::MountCorrection> mount_;
  std::string command_;
  bool quiet_;
};

}  // namespace mlmap::cli
