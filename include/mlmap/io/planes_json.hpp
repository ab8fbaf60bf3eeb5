// The planes JSON export (schema "mlmap.planes/1", web/planes.schema.json): every
// patch with its class, plane, centroid, area, outline and fit, and the map's
// metadata, parameters and timings. Read by the web dashboard.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "mlmap/map/map.hpp"
#include "mlmap/planes/ermsm.hpp"

namespace mlmap::io {

constexpr const char* kPlanesSchema = "mlmap.planes/1";

// The export as JSON text: a member per line, a plane per line, positions (centroids,
// outlines) rounded to the micrometre. Planes and bounds in the world's coordinates, or
// with `in_map_frame` in the map's (the dashboard: a national grid's coordinates are too
// large for a browser's float); map.origin says where the map's frame lies, where it is
// not the world's (`detection` holds the planes in the map's frame, as detectPlanes
// found them).
std::string planesJson(const Map& map, const PlaneDetection& detection, const std::string& source_name,
                       bool in_map_frame = false);

// Written atomically.
void writePlanesJson(const std::filesystem::path& path, const Map& map, const PlaneDetection& detection,
                     const std::string& source_name);

// Reads an export back: the planes with their parameters and run figures (the map's
// own metadata is the map's, not kept). Input is untrusted: anything off the schema
// throws mlmap::Error naming `name` and the element, e.g. "x.json: planes[3].normal: ...".
PlaneDetection parsePlanesJson(std::string_view text, const std::string& name);
PlaneDetection readPlanesJson(const std::filesystem::path& path);

}  // namespace mlmap::io
