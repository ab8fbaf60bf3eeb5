#include "creases.hpp"

#include <vector>

#include "crease_faces.hpp"
#include "step_faces.hpp"

namespace mlmap {
namespace {

// A patch whose points lie within this many σ of its plane (RMS) is flat to its noise and
// not looked at (plane_seg's cinder compromise: 2.1 σ; the PCL room scans' distorted
// ceilings reach 2.1 σ too, and are left whole by the crease rule, not by this).
constexpr double kRoughSigmas = 1.5;

}  // namespace

std::vector<int> splitCreases(const BlockGrid& grid, PatchSet& set, const CreaseConfig& config) {
  std::vector<int> split;  // per plane: the patch it was split from, -1 for none
  if (config.noise <= 0.0) return split;
  const std::size_t count = set.planes.size();
  for (std::size_t k = 0; k < count; ++k) {
    const Plane& plane = set.planes[k];
    if (!(plane.rms > kRoughSigmas * config.noise) || set.blocks[k].size() < 2 * static_cast<std::size_t>(config.min_blocks))
      continue;
    if (grid.pointsOf(set.blocks[k].front()).empty()) return split;  // a map without point moments
    std::vector<std::vector<std::size_t>> faces = creaseFaces(grid, set, k, config);
    if (faces.empty()) faces = stepFaces(grid, set, k, config);
    if (faces.empty()) continue;
    const std::vector<std::uint32_t> blocks = set.blocks[k];
    const Plane original = set.planes[k];
    for (const std::uint32_t id : blocks) set.labels[id] = 0;  // those on no face stay so
    bool first = true;
    for (const std::vector<std::size_t>& face : faces) {
      std::vector<std::uint32_t> ids;
      for (const std::size_t b : face) ids.push_back(blocks[b]);
      std::sort(ids.begin(), ids.end());
      // The face's plane from its blocks (the block sums of a patch's description).
      Patch whole;
      whole.blocks = ids;
      const CandidatePlane reference{original.normal.cast<float>(), original.centroid.cast<float>()};
      const Plane fitted = describePatch(grid, whole, reference, config.kappa_rad, config.noise);
      for (Patch& piece : splitIntoPatches(grid, ids, fitted.normal, fitted.centroid)) {
        if (tooSmallForFace(piece.blocks.size(), piece.surface, grid.cellSize(), config)) {
          for (const std::uint32_t id : piece.blocks) set.labels[id] = 0;
          continue;
        }
        Plane described = describePatch(grid, piece, {fitted.normal.cast<float>(), fitted.centroid.cast<float>()},
                                        config.kappa_rad, config.noise);
        described.source = original.source;
        described.candidates = original.candidates;
        const OutlineFrame frame{described.normal, described.centroid, true};
        placePatch(set, first ? k : set.planes.size(), std::move(described), std::move(piece.blocks), frame);
        first = false;
      }
    }
    if (first) {  // every piece too small: the patch as it was
      set.planes[k] = original;
      set.blocks[k] = blocks;
      for (const std::uint32_t id : blocks) set.labels[id] = original.id;
    } else {
      split.resize(set.planes.size(), -1);
      split[k] = static_cast<int>(k);
      for (std::size_t f = split.size(); f-- > 0 && f >= count;)
        if (split[f] < 0) split[f] = static_cast<int>(k);
    }
  }
  return split;
}

}  // namespace mlmap
