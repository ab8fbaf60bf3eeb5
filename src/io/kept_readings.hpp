// Internal to the io module: a scan keeps the readings a filter lets through, with their
// variances and labels where it carries them (one per reading).
#pragma once

#include <cstddef>

#include "mlmap/scan.hpp"

namespace mlmap::io {

// Keeps reading k where keep(k); returns how many went.
template <typename Keep>
std::size_t keepReadings(Scan& scan, Keep&& keep) {
  const std::size_t count = scan.size();
  const bool with_variances = scan.variances.size() == count;
  const bool with_labels = scan.labels.size() == count;
  std::size_t kept = 0;
  for (std::size_t k = 0; k < count; ++k) {
    if (!keep(k)) continue;
    scan.points[kept] = scan.points[k];
    if (with_variances) scan.variances[kept] = scan.variances[k];
    if (with_labels) scan.labels[kept] = scan.labels[k];
    ++kept;
  }
  scan.points.resize(kept);
  if (with_variances) scan.variances.resize(kept);
  if (with_labels) scan.labels.resize(kept);
  return count - kept;
}

}  // namespace mlmap::io
