// Every scan of a list of files, in order, with pose i of a TUM file when one is
// given (scan i is in its sensor frame, pose i maps it to the world). build, label
// and register read their inputs this way, with one rule for a pose file whose count
// differs from the scans'.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "mlmap/io/tum_poses.hpp"
#include "mlmap/scan.hpp"

namespace mlmap::cli {

// Calls visit(scan, index, file) for every scan, then file_done(file) after each file.
// Without poses each scan keeps its own. Throws mlmap::Error naming the pose file when
// it holds fewer or more poses than there are scans.
void forEachPosedScan(const std::vector<std::string>& files, const std::vector<io::StampedPose>& poses,
                      const std::string& poses_path,
                      const std::function<void(Scan& scan, std::size_t index, std::size_t file)>& visit,
                      const std::function<void(std::size_t file)>& file_done = {});

}  // namespace mlmap::cli
