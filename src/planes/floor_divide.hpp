// Internal to eRMSM: integer division rounding towards −∞, for cell indices (negative
// on the far side of the map's origin) grouped into coarser cells or buckets.
#pragma once

#include <cstdint>

namespace mlmap {

// `divisor` > 0.
inline std::int64_t floorDivide(std::int64_t value, std::int64_t divisor) {
  return value >= 0 ? value / divisor : -((-value + divisor - 1) / divisor);
}

}  // namespace mlmap
