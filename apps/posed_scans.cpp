#include "posed_scans.hpp"

#include "mlmap/error.hpp"
#include "mlmap/io/scan_file.hpp"

namespace mlmap::cli {

void forEachPosedScan(const std::vector<std::string>& files, const std::vector<io::StampedPose>& poses,
                      const std::string& poses_path,
                      const std::function<void(Scan& scan, std::size_t index, std::size_t file)>& visit,
                      const std::function<void(std::size_t file)>& file_done) {
  std::size_t index = 0;
  for (std::size_t file = 0; file < files.size(); ++file) {
    // One file at a time, so memory holds the work, not every scan.
    for (Scan& scan : io::readScans(files[file])) {
      if (!poses.empty()) {
        if (index >= poses.size()) {
          throw Error(poses_path + ": " + std::to_string(poses.size()) + " poses, but there are more scans (" +
                      files[file] + " is scan " + std::to_string(index + 1) + ")");
        }
        scan.pose = poses[index].pose;
      }
      visit(scan, index, file);
      ++index;
    }
    if (file_done) file_done(file);
  }
  if (!poses.empty() && index != poses.size()) {
    throw Error(poses_path + ": " + std::to_string(poses.size()) + " poses for " + std::to_string(index) +
                " scans");
  }
}

}  // namespace mlmap::cli
