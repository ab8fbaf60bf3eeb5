// Colours for planes, the same in every export (octovis, PLY, the web dashboard): a
// plane's colour depends only on its id, so it stays put when other planes change.
#pragma once

#include <cstdint>

namespace mlmap::io {

struct Rgb {
  std::uint8_t red = 0;
  std::uint8_t green = 0;
  std::uint8_t blue = 0;
  friend bool operator==(const Rgb&, const Rgb&) = default;
};

constexpr Rgb kUnlabelledColour{150, 150, 150};

// Hues spread by the golden angle, so neighbouring ids differ strongly; id 0 (no
// plane) is grey. The dashboard's "colour by id" uses the same formula.
Rgb planeColour(std::int32_t plane_id);

}  // namespace mlmap::io
