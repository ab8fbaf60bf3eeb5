// The web dashboard, exported beside its data so it opens from disk (file://) or
// from any static server: the built page (web/dist/index.html, self-contained) as
// DIR/index.html, the planes as DIR/planes.json, and the same JSON as DIR/planes.js
// (`window.MLMAP_PLANES = ...;`), which the page loads with a plain script tag because
// browsers refuse fetch() on file:// pages.
#pragma once

#include <filesystem>
#include <string>

namespace mlmap::io {

// Each file written atomically; DIR is created when missing. Throws mlmap::Error
// when the page cannot be read.
void writeDashboard(const std::filesystem::path& directory, const std::filesystem::path& page,
                    const std::string& planes_json);

}  // namespace mlmap::io
