// Internal to the scene loader. A scene file is read in two layers: scene.cpp parses one
// file's own elements (poses, scan pattern, surfaces), scene_include.cpp places the
// included files, cuts the openings and expresses the result in the output frame.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "json_node.hpp"
#include "mlmap/sim/scene.hpp"
#include "mlmap/sim/placement.hpp"

namespace mlmap::sim::detail {

// A loaded scene file: the scene in its output frame (the frame of the scene that
// provides the poses) and that frame's placement in the file's own frame.
struct LoadedScene {
  Scene scene;
  Placement frame;  // identity when the file has its own poses
};

// Files being loaded, outermost first (canonical paths, for the cycle check).
using IncludeChain = std::vector<std::filesystem::path>;

// Reads and parses a scene document; errors name `source`.
nlohmann::json parseSceneDocument(std::string_view json_text, const std::string& source);
nlohmann::json readSceneDocument(const std::filesystem::path& path);

// The file's own name, scan_pattern, odometry, poses and surfaces (plane ids from 0, in
// the file's frame); poses and surfaces may be absent unless required.
Scene parseSceneElements(const JsonNode& root, bool poses_required, bool surfaces_required);

// The whole scene of a document: includes placed, openings cut, in the output frame.
// `directory` resolves include paths; `poses_required` is false for an include that
// does not provide the poses (such a file may have none).
LoadedScene assembleScene(const nlohmann::json& document, const std::string& source,
                          const std::filesystem::path& directory, IncludeChain& chain,
                          bool poses_required);

}  // namespace mlmap::sim::detail
