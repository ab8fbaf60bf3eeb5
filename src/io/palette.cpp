#include "mlmap/io/palette.hpp"

#include <cmath>

namespace mlmap::io {
namespace {

Rgb fromHsv(double hue, double saturation, double value) {
  const double sector = hue * 6.0;
  const int whole = static_cast<int>(std::floor(sector)) % 6;
  const double fraction = sector - std::floor(sector);
  const double p = value * (1.0 - saturation);
  const double q = value * (1.0 - saturation * fraction);
  const double t = value * (1.0 - saturation * (1.0 - fraction));
  double r = value, g = t, b = p;
  switch (whole) {
    case 1: r = q; g = value; b = p; break;
    case 2: r = p; g = value; b = t; break;
    case 3: r = p; g = q; b = value; break;
    case 4: r = t; g = p; b = value; break;
    case 5: r = value; g = p; b = q; break;
    default: break;
  }
  const auto byte = [](double channel) { return static_cast<std::uint8_t>(std::lround(channel * 255.0)); };
  return {byte(r), byte(g), byte(b)};
}

}  // namespace

Rgb planeColour(std::int32_t plane_id) {
  if (plane_id <= 0) return kUnlabelledColour;
  constexpr double kGoldenRatioConjugate = 0.6180339887498949;
  const double hue = std::fmod(0.1 + plane_id * kGoldenRatioConjugate, 1.0);
  // Alternate brightness too, so ids whose hues come close still differ.
  return fromHsv(hue, 0.7, plane_id % 2 == 0 ? 0.8 : 0.95);
}

}  // namespace mlmap::io
