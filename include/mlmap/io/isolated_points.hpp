// Floating outliers: readings with too few others near them in their own scan (a depth
// camera's flying pixels, dust, rain), like PCL's RadiusOutlierRemoval. Off by default:
// a scanner's far readings are as lonely (the real scans of ../shared/data at 0.1 m and
// two neighbours: 1.5-10 % of 3DTK's, OctoMap's scan.dat and PCL's room scans, a few
// hundred of them on walls), so it is for dense clouds that float points in free space.
#pragma once

#include <cstddef>

#include "mlmap/scan.hpp"

namespace mlmap::io {

struct IsolationFilter {
  double radius = 0.0;     // m; 0: keep every reading
  int min_neighbours = 2;  // others within the radius a reading needs to stay

  bool enabled() const { return radius > 0.0 && min_neighbours > 0; }
};

// Drops the scan's readings (sensor frame) with fewer than filter.min_neighbours other
// readings within filter.radius, with their variances and labels. Returns how many.
std::size_t dropIsolated(Scan& scan, const IsolationFilter& filter);

}  // namespace mlmap::io
