// Internal to the scene loader (scene.cpp): the surface elements of a scene file
// (rectangle, box, stairs, cylinder), each read through its JsonNode into the surfaces
// still waiting for their plane ids.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "json_node.hpp"
#include "mlmap/sim/scene.hpp"

namespace mlmap::sim::detail {

// A surface before plane ids are assigned.
struct PendingSurface {
  Surface surface;
  std::optional<std::int32_t> plane_id;
  SurfaceClass surface_class = SurfaceClass::Other;
  std::string name;
  std::string path;  // JSON element, for messages
  int auto_group = -1;  // surfaces with the same group >= 0 share one auto-assigned id
};

struct SceneBuilder {
  std::vector<PendingSurface> surfaces;
  int next_group = 0;
};

void parseRectangle(const JsonNode& node, SceneBuilder& builder);
// A box's faces, each its own surface (some left out, some with their own class or plane).
void parseBox(const JsonNode& node, SceneBuilder& builder);
// A flight: each tread and riser its own surface, the sides' faces too.
void parseStairs(const JsonNode& node, SceneBuilder& builder);
void parseCylinder(const JsonNode& node, Scene& scene);

}  // namespace mlmap::sim::detail
