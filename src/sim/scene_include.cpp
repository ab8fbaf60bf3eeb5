// Scene includes: the assembly of a scene file from its includes (each placed in the
// file's frame), its own elements and its openings, in the output frame.
#include <algorithm>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "mlmap/error.hpp"
#include "mlmap/sim/openings.hpp"
#include "mlmap/sim/placement.hpp"
#include "scene_loader.hpp"

namespace mlmap::sim {
namespace detail {
namespace {

constexpr std::size_t kMaxIncludeDepth = 4;  // includes of includes ... below the top file

// Appends `part` with its plane ids moved past the largest id already in `scene` (so
// the first part keeps its ids) and its plane names prefixed "part/".
void appendPart(Scene& scene, Scene part, const std::string& prefix) {
  const std::int32_t offset = scene.ground_truth.empty() ? 0 : scene.ground_truth.back().id + 1;
  if (!part.ground_truth.empty() &&
      part.ground_truth.back().id > std::numeric_limits<std::int32_t>::max() - offset) {
    throw Error(prefix + ": plane ids overflow");
  }
  for (Surface& surface : part.surfaces) {
    surface.plane_id += offset;
    scene.surfaces.push_back(surface);
  }
  for (GroundTruthPlane& plane : part.ground_truth) {
    plane.id += offset;
    if (!prefix.empty()) plane.name = prefix + "/" + plane.name;
    scene.ground_truth.push_back(std::move(plane));
  }
  scene.cylinders.insert(scene.cylinders.end(), part.cylinders.begin(), part.cylinders.end());
}

std::string describeChain(const IncludeChain& chain, const std::filesystem::path& next) {
  std::string text;
  for (const auto& path : chain) text += path.filename().string() + " -> ";
  return text + next.filename().string();
}

// One part of the scene: an include (loaded recursively) or the file's own elements.
struct Part {
  Scene scene;        // in the part's output frame
  Placement to_file;  // the part's output frame in the including file's frame
  std::string name;   // prefix of its plane names ("" for the file's own)
};

Part loadInclude(const JsonNode& item, const std::filesystem::path& directory, IncludeChain& chain,
                 bool provides_poses) {
  const JsonNode scene_node = item["scene"];
  const std::filesystem::path path = directory / scene_node.string();
  if (!std::filesystem::is_regular_file(path)) scene_node.fail("cannot open scene file " + path.string());
  std::error_code ignored;
  const std::filesystem::path canonical = std::filesystem::weakly_canonical(path, ignored);
  if (std::find(chain.begin(), chain.end(), canonical) != chain.end()) {
    scene_node.fail("include cycle " + describeChain(chain, canonical));
  }
  if (chain.size() > kMaxIncludeDepth) {
    scene_node.fail("includes nested more than " + std::to_string(kMaxIncludeDepth) + " deep");
  }

  chain.push_back(canonical);
  LoadedScene loaded;
  try {
    loaded = assembleScene(readSceneDocument(path), path.string(), path.parent_path(), chain, provides_poses);
  } catch (const Error& error) {
    item.fail(error.what());
  }
  chain.pop_back();

  const Placement placement{item.numberOr("x", 0.0), item.numberOr("y", 0.0), item.numberOr("yaw_deg", 0.0)};
  Part part;
  part.to_file = compose(placement, loaded.frame);
  part.name = loaded.scene.name.empty() ? path.stem().string() : loaded.scene.name;
  part.scene = std::move(loaded.scene);
  return part;
}

// Openings are boxes in the file's frame, placed at `file_frame` in the output frame.
void cutOpenings(const JsonNode& openings, Scene& scene, const Placement& file_frame) {
  for (std::size_t i = 0; i < openings.arraySize(); ++i) {
    const JsonNode node = openings[i];
    node.allowOnly({"min", "max", "name"});
    Opening opening;
    opening.min = node["min"].vector3();
    opening.max = node["max"].vector3();
    opening.name = node.stringOr("name", opening.name);
    if ((opening.max - opening.min).minCoeff() <= 0.0) node["max"].fail("must be above min in x, y and z");
    try {
      cutOpening(scene, opening, file_frame);
    } catch (const Error& error) {
      node.fail(error.what());
    }
  }
}

}  // namespace

LoadedScene assembleScene(const nlohmann::json& document, const std::string& source,
                          const std::filesystem::path& directory, IncludeChain& chain, bool poses_required) {
  const JsonNode root(document, "", source);
  root.allowOnly({"name", "scan_pattern", "odometry", "poses", "surfaces", "include", "openings"});
  LoadedScene result;
  if (!root.has("include")) {
    result.scene = parseSceneElements(root, poses_required, true);
    if (root.has("openings")) cutOpenings(root["openings"], result.scene, {});
    return result;
  }

  const bool own_poses = root.has("poses");
  if (!own_poses) {
    for (const char* key : {"scan_pattern", "odometry"}) {
      if (root.has(key)) root[key].fail("only beside poses (the include with \"poses\": true brings its own)");
    }
  }
  std::vector<Part> parts;
  std::optional<std::size_t> provider;
  const JsonNode includes = root["include"];
  for (std::size_t i = 0; i < includes.arraySize(); ++i) {
    const JsonNode item = includes[i];
    item.allowOnly({"scene", "x", "y", "yaw_deg", "poses"});
    const bool provides = item.has("poses") && item["poses"].boolean();
    if (provides && own_poses) item["poses"].fail("this file has its own poses: only one scene may provide them");
    if (provides && provider) {
      item["poses"].fail("include[" + std::to_string(*provider) + "] already provides the poses");
    }
    if (provides) provider = i;
    parts.push_back(loadInclude(item, directory, chain, provides));
  }
  if (!own_poses && !provider && poses_required) {
    throw Error(source + ": poses: missing (give poses, or \"poses\": true in one include)");
  }
  parts.push_back({parseSceneElements(root, false, false), Placement{}, ""});
  const Scene& with_poses = parts[provider.value_or(parts.size() - 1)].scene;

  // The output frame is the provider's: it keeps its coordinates exactly, every other
  // part moves from its frame to the file's and on to the provider's.
  result.frame = provider ? parts[*provider].to_file : Placement{};
  const Placement to_output = inverse(result.frame);
  Scene& scene = result.scene;
  scene.name = parts.back().scene.name;
  scene.pattern = with_poses.pattern;
  scene.odometry = with_poses.odometry;
  scene.poses = with_poses.poses;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    Part& part = parts[i];
    if (i != provider) transformScene(part.scene, compose(to_output, part.to_file));
    appendPart(scene, std::move(part.scene), part.name);
  }
  if (scene.ground_truth.empty()) throw Error(source + ": expected at least one planar surface");
  if (root.has("openings")) cutOpenings(root["openings"], scene, to_output);
  return result;
}

}  // namespace detail
}  // namespace mlmap::sim
