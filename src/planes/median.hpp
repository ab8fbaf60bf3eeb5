// Internal to eRMSM: the median of a list of values (the upper one of an even count),
// reordering the list; the noise estimate and the patch rules each take one.
#pragma once

#include <algorithm>
#include <vector>

namespace mlmap {

// `values` must not be empty.
inline float medianOf(std::vector<float>& values) {
  const auto middle = values.begin() + static_cast<long>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace mlmap
