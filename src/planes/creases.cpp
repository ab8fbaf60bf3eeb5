#include "creases.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "mlmap/map/point_stats.hpp"

namespace mlmap {
namespace {

// A patch whose points lie within this many σ of its plane (RMS) is flat to its noise and
// not looked at (plane_seg's cinder compromise: 2.1 σ; the PCL room scans' distorted
// ceilings reach 2.1 σ too, and are left whole by the crease rule, not by this).
constexpr double kRoughSigmas = 1.5;
// The faces' squared residuals must be at most this share of the one plane's: their RMS
// half (the cinder compromise 0.11, its synthetic twin in tests/test_planes_creases.cpp
// 0.08; a depth camera's layered wall in PCL's office1, once its layers are one face, 0.72).
constexpr double kSplitGain = 0.25;
// At most this share of a patch's points may lie off every face by more than 3 σ (RMS).
constexpr double kOffFaces = 0.15;
// A face grown from the windows lacks its rim, whose windows straddle the crease (a ring a
// cell wide: 44 % of a 0.4 m face at 5 cm cells); its pieces, rim included, are held to the
// patches' minimum area.
constexpr double kFaceShare = 0.5;
// A face's points spread at least this far (standard deviation) across it both ways.
constexpr double kFaceSpreadCells = 0.5;
// A window's plane needs this many points, spread across at least a quarter cell both ways
// (a single scan line through it leaves its tilt about the line free).
constexpr double kWindowPoints = 8.0;
constexpr double kWindowSpreadCells = 0.25;

struct Window {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double rms = 0.0;
  bool valid = false;
};

struct Face {
  PointMoments points;  // about the patch's origin
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // relative to the origin
  std::vector<std::size_t> members;                 // indices into the patch's blocks
};

void fitFace(Face& face) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(face.points.covariance());
  face.normal = solver.eigenvectors().col(0);
  face.point = face.points.mean();
}

// Mean squared distance of a block's points from a plane (both about the same origin).
double meanSquared(const PointStats& stats, const Eigen::Vector3d& centre, const Eigen::Vector3d& normal,
                   const Eigen::Vector3d& point) {
  const double along = normal.dot(centre + stats.mean() - point);
  return along * along + normal.dot(stats.scatterMatrix() * normal) / static_cast<double>(stats.count);
}

double angleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(std::abs(a.dot(b)), 0.0, 1.0));
}

// The faces of one patch (indices into its blocks), or none when one plane explains it.
std::vector<std::vector<std::size_t>> facesOf(const BlockGrid& grid, const PatchSet& set, std::size_t k,
                                              const CreaseConfig& config) {
  const std::vector<std::uint32_t>& blocks = set.blocks[k];
  const Plane& plane = set.planes[k];
  const std::size_t count = blocks.size();
  const auto label = static_cast<std::int32_t>(k + 1);
  const double cell = grid.cellSize();
  const Eigen::Vector3d origin = plane.centroid;
  std::vector<PointStats> stats(count);
  std::vector<Eigen::Vector3d> centres(count);
  std::unordered_map<std::uint32_t, std::size_t> index;
  index.reserve(count);
  for (std::size_t b = 0; b < count; ++b) {
    stats[b] = grid.pointsOf(blocks[b]);
    centres[b] = (Eigen::Vector3d() << grid.cellCentre(grid.blocks()[blocks[b]].cell), 0.0).finished() - origin;
    index.emplace(blocks[b], b);
  }
  const auto forNeighbours = [&](std::size_t b, auto&& visit) {
    grid.forEachNeighbour(grid.blocks()[blocks[b]].cell, 1, [&](std::uint32_t other) {
      if (set.labels[other] == label) visit(index.at(other));
    });
  };
  // Each block's window: its points and its patch neighbours' within one cell.
  std::vector<Window> windows(count);
  for (std::size_t b = 0; b < count; ++b) {
    PointMoments points;
    forNeighbours(b, [&](std::size_t o) { points.add(stats[o], centres[o]); });
    if (points.count < kWindowPoints) continue;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(points.covariance());
    if (solver.eigenvalues()(1) < std::pow(kWindowSpreadCells * cell, 2)) continue;
    Eigen::Vector3d normal = solver.eigenvectors().col(0);
    if (normal.dot(plane.normal) < 0.0) normal = -normal;
    windows[b] = {normal, std::sqrt(std::max(0.0, solver.eigenvalues()(0))), true};
  }
  // Faces grown from the flattest windows over neighbours whose windows turn less than
  // κ / 3 (8.3°) from the face's mean: between the cinder faces' 13° and what one surface's
  // windows turn by where it is warped or layered (room_scan2's wall x-2.55: pieces 0.5-5°
  // apart; office1's far wall: layers 1.8° apart).
  const double grow = config.kappa_rad / 3.0;
  std::vector<std::size_t> order;
  for (std::size_t b = 0; b < count; ++b)
    if (windows[b].valid) order.push_back(b);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return windows[a].rms < windows[b].rms; });
  std::vector<int> face_of(count, -1);
  std::vector<Face> faces;
  for (const std::size_t seed : order) {
    if (face_of[seed] >= 0) continue;
    Face face;
    Eigen::Vector3d sum = windows[seed].normal;
    const int id = static_cast<int>(faces.size());
    face_of[seed] = id;
    std::vector<std::size_t> queue{seed};
    for (std::size_t q = 0; q < queue.size(); ++q) {
      face.members.push_back(queue[q]);
      const Eigen::Vector3d mean = sum.normalized();
      forNeighbours(queue[q], [&](std::size_t o) {
        if (face_of[o] >= 0 || !windows[o].valid || angleBetween(windows[o].normal, mean) > grow) return;
        face_of[o] = id;
        sum += windows[o].normal;
        queue.push_back(o);
      });
    }
    faces.push_back(std::move(face));
  }
  // Faces large enough for a patch, fitted to their own blocks' points.
  const double cell_area = cell * cell;
  std::vector<Face> large;
  for (Face& face : faces) {
    double surface = 0.0;
    for (const std::size_t b : face.members) surface += grid.blocks()[blocks[b]].surface;
    if (face.members.size() < static_cast<std::size_t>(config.min_blocks) || surface * cell_area < kFaceShare * config.min_area)
      continue;
    for (const std::size_t b : face.members) face.points.add(stats[b], centres[b]);
    // Its points spread across the face both ways (a row of blocks along one scan line
    // fits any plane through the line).
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(face.points.covariance());
    if (solver.eigenvalues()(1) < std::pow(kFaceSpreadCells * cell, 2)) continue;
    // ... and off its plane by about the noise: points of one or two scan lines lie in the
    // scanner's sweep plane whatever the surface (room_scan2's wall x-2.55 at 5 cm: 12
    // points, RMS 0, 61° off the wall).
    if (solver.eigenvalues()(0) < std::pow(config.noise / 3.0, 2)) continue;
    fitFace(face);
    large.push_back(std::move(face));
  }
  // Faces whose planes turn less than a window may are one: touching (a surface that
  // bends or warps, a scanner's distortion, rather than creases) or on one plane (a face
  // cut in two by a crease's windows).
  std::vector<int> large_of(count, -1);
  for (std::size_t f = 0; f < large.size(); ++f)
    for (const std::size_t b : large[f].members) large_of[b] = static_cast<int>(f);
  // Whether a block of `members` has a neighbour that `face_of` gives to face `other`.
  const auto touches = [&](const std::vector<std::size_t>& members, const std::vector<int>& face_of, std::size_t other) {
    for (const std::size_t m : members) {
      bool found = false;
      forNeighbours(m, [&](std::size_t o) { found = found || face_of[o] == static_cast<int>(other); });
      if (found) return true;
    }
    return false;
  };
  const auto touching = [&](std::size_t a, std::size_t b) { return touches(large[a].members, large_of, b); };
  for (std::size_t a = 0; a < large.size(); ++a) {
    for (std::size_t b = a + 1; b < large.size();) {
      const bool coplanar = std::abs(large[a].normal.dot(large[b].point - large[a].point)) <= config.epsilon &&
                            std::abs(large[b].normal.dot(large[a].point - large[b].point)) <= config.epsilon;
      if (angleBetween(large[a].normal, large[b].normal) > grow || !(coplanar || touching(a, b))) {
        ++b;
        continue;
      }
      for (const std::size_t m : large[b].members) large_of[m] = static_cast<int>(a);
      large[a].points.merge(large[b].points);
      large[a].members.insert(large[a].members.end(), large[b].members.begin(), large[b].members.end());
      fitFace(large[a]);
      large.erase(large.begin() + static_cast<std::ptrdiff_t>(b));
      for (int& f : large_of)
        if (f > static_cast<int>(b)) --f;
      b = a + 1;
    }
  }
  // Every block to the face its points lie nearest. A face left with less than a face needs
  // (a rim's windows, a corner, a depth camera's clutter) gives its blocks to the others.
  const Eigen::Vector3d patch_point = -(plane.normal.dot(origin) + plane.offset) * plane.normal;
  std::vector<std::vector<std::size_t>> members;
  std::vector<double> squared;  // per face, its members' points' squared residuals
  while (large.size() >= 2) {
    members.assign(large.size(), {});
    squared.assign(large.size(), 0.0);
    for (std::size_t b = 0; b < count; ++b) {
      if (stats[b].empty()) continue;
      std::size_t best = 0;
      double best_squared = std::numeric_limits<double>::infinity();
      for (std::size_t f = 0; f < large.size(); ++f) {
        const double mean_squared = meanSquared(stats[b], centres[b], large[f].normal, large[f].point);
        if (mean_squared < best_squared) best = f, best_squared = mean_squared;
      }
      // A block whose points lie off every face by more than 3 σ (RMS) is on none: a
      // cinder block's side, a crease's cell at 10 cm (neither counts for or against).
      if (best_squared > std::pow(3.0 * config.noise, 2)) continue;
      members[best].push_back(b);
      squared[best] += stats[b].count * best_squared;
    }
    std::vector<double> surfaces(large.size(), 0.0);
    for (std::size_t f = 0; f < large.size(); ++f)
      for (const std::size_t b : members[f]) surfaces[f] += grid.blocks()[blocks[b]].surface;
    // The smallest of the faces too small.
    std::size_t smallest = large.size();
    for (std::size_t f = 0; f < large.size(); ++f) {
      const bool small = members[f].size() < static_cast<std::size_t>(config.min_blocks) ||
                         surfaces[f] * cell_area < kFaceShare * config.min_area;
      if (small && (smallest == large.size() || surfaces[f] < surfaces[smallest])) smallest = f;
    }
    if (smallest < large.size()) {
      large.erase(large.begin() + static_cast<std::ptrdiff_t>(smallest));
      continue;
    }
    // Faces that now touch and turn less than a window may are one surface in layers or
    // warped (a depth camera's wall: two layers 16 cm apart that the windows had kept
    // apart): one face, fitted to the blocks both took.
    std::vector<int> face_of(count, -1);
    for (std::size_t f = 0; f < large.size(); ++f)
      for (const std::size_t b : members[f]) face_of[b] = static_cast<int>(f);
    bool merged = false;
    for (std::size_t a = 0; a < large.size() && !merged; ++a) {
      for (std::size_t b = a + 1; b < large.size() && !merged; ++b) {
        if (angleBetween(large[a].normal, large[b].normal) > grow || !touches(members[a], face_of, b)) continue;
        large[a].points = PointMoments{};
        for (const std::size_t f : {a, b})
          for (const std::size_t m : members[f]) large[a].points.add(stats[m], centres[m]);
        fitFace(large[a]);
        large.erase(large.begin() + static_cast<std::ptrdiff_t>(b));
        merged = true;
      }
    }
    if (!merged) break;
  }
  if (large.size() < 2) return {};
  // A crease: two touching faces that turn more than a window may. Faces all within that
  // of each other are parallel layers or one warped surface, not creased (room_scan2's
  // wall x-2.55, warped by ±10 cm: pieces 0.5-5° apart and 5-10 cm off each other).
  std::vector<int> assigned(count, -1);
  for (std::size_t f = 0; f < large.size(); ++f)
    for (const std::size_t b : members[f]) assigned[b] = static_cast<int>(f);
  bool creased = false;
  for (std::size_t a = 0; a < large.size() && !creased; ++a)
    for (std::size_t b = a + 1; b < large.size() && !creased; ++b)
      creased = angleBetween(large[a].normal, large[b].normal) > grow && touches(members[a], assigned, b);
  if (!creased) return {};
  // The split stands when the faces' squared residuals are at most a quarter of the one
  // plane's over the same blocks ...
  double one = 0.0;
  for (const std::vector<std::size_t>& face : members)
    for (const std::size_t b : face) one += stats[b].count * meanSquared(stats[b], centres[b], plane.normal, patch_point);
  const double split = std::accumulate(squared.begin(), squared.end(), 0.0);
  if (!(split <= kSplitGain * one)) return {};
  // ... and the faces hold most of the patch's points: where over 15 % lie off every face
  // (a depth camera's layered wall: 34 %; ANYmal's treads and risers of a 2 cm elevation
  // map: 24 %) the faces are not what the patch is made of (the cinder blocks at 10 cm
  // cells: 10 %, at 5 cm 2.5 %).
  double all = 0.0;
  double on_faces = 0.0;
  for (std::size_t b = 0; b < count; ++b) all += stats[b].count;
  for (const std::vector<std::size_t>& face : members)
    for (const std::size_t b : face) on_faces += stats[b].count;
  if (on_faces < (1.0 - kOffFaces) * all) return {};
  return members;
}

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
    const std::vector<std::vector<std::size_t>> faces = facesOf(grid, set, k, config);
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
        double surface = 0.0;
        for (const std::uint32_t id : piece.blocks) surface += grid.blocks()[id].surface;
        piece.surface = surface;
        const bool large = piece.blocks.size() >= static_cast<std::size_t>(config.min_blocks) &&
                           surface * grid.cellSize() * grid.cellSize() >= kFaceShare * config.min_area;
        if (!large) {
          for (const std::uint32_t id : piece.blocks) set.labels[id] = 0;
          continue;
        }
        Plane described = describePatch(grid, piece, {fitted.normal.cast<float>(), fitted.centroid.cast<float>()},
                                        config.kappa_rad, config.noise);
        described.source = original.source;
        described.candidates = original.candidates;
        const OutlineFrame frame{described.normal, described.centroid, true};
        std::size_t slot = k;
        if (first) {
          first = false;
          described.id = original.id;
        } else {
          slot = set.planes.size();
          described.id = static_cast<std::int32_t>(slot + 1);
          set.planes.emplace_back();
          set.blocks.emplace_back();
          set.outline_frames.emplace_back();
          set.outline_runs.emplace_back();
        }
        for (const std::uint32_t id : piece.blocks) set.labels[id] = described.id;
        set.planes[slot] = std::move(described);
        set.blocks[slot] = std::move(piece.blocks);
        set.outline_frames[slot] = frame;
        set.outline_runs[slot] = {};
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
