#include "crease_faces.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>
#include <vector>

#include "mlmap/map/point_stats.hpp"

namespace mlmap {
namespace {

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
// A block may go to a face whose windows' blocks lie within this many neighbour steps of it:
// the rim a face grown from windows lacks is a ring a cell wide. Two steps let the faces
// of plane_seg's ANYmal stairs (a 2 cm elevation map) at 5 cm cells creep, round after
// round, from the smoothed risers' slopes into the treads.
constexpr int kReachSteps = 1;
// Rounds of assigning the blocks to the faces and refitting the faces, at most (the
// cinder field settles in two to four).
constexpr int kAssignRounds = 8;
// A face grown from windows seeds a face from 2 x 2 blocks on (see seedBlocks).
constexpr int kSeedFaceBlocks = 4;


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

// One patch's blocks (indexed 0..n-1 here), their points' moments about the patch's
// centroid, and the steps that find its faces.
class PatchFaces {
 public:
  PatchFaces(const BlockGrid& grid, const PatchSet& set, std::size_t k, const CreaseConfig& config)
      : grid_(grid), set_(set), blocks_(set.blocks[k]), plane_(set.planes[k]), label_(static_cast<std::int32_t>(k + 1)),
        config_(config), grow_(config.kappa_rad / 3.0),
        stats_(blocks_.size()), centres_(blocks_.size()) {
    const Eigen::Vector3d origin = plane_.centroid;
    index_.reserve(blocks_.size());
    for (std::size_t b = 0; b < blocks_.size(); ++b) {
      stats_[b] = grid.pointsOf(blocks_[b]);
      centres_[b] = grid.pointsFrameOf(blocks_[b]) - origin;
      index_.emplace(blocks_[b], b);
    }
    patch_point_ = -(plane_.normal.dot(origin) + plane_.offset) * plane_.normal;
  }

  // The faces (indices into the patch's blocks), or none when one plane explains it.
  std::vector<std::vector<std::size_t>> find() {
    std::vector<Face> faces = largeFaces(grownFaces(windows()));
    mergeTouchingOrCoplanar(faces);
    std::vector<std::vector<std::size_t>> members;
    std::vector<double> squared;
    assign(faces, members, squared);
    if (faces.size() < 2 || !creased(faces, members) || !explained(members, squared)) return {};
    return members;
  }

 private:
  template <typename Visit>
  void forNeighbours(std::size_t b, Visit&& visit) const {
    grid_.forEachNeighbour(grid_.blocks()[blocks_[b]].cell, 1, [&](std::uint32_t other) {
      if (set_.labels[other] == label_) visit(index_.at(other));
    });
  }

  double surfaceOf(const std::vector<std::size_t>& members) const {
    double surface = 0.0;
    for (const std::size_t b : members) surface += grid_.blocks()[blocks_[b]].surface;
    return surface;
  }

  // Whether a block of `members` has a neighbour that `face_of` gives to face `other`.
  bool touches(const std::vector<std::size_t>& members, const std::vector<int>& face_of, std::size_t other) const {
    for (const std::size_t m : members) {
      bool found = false;
      forNeighbours(m, [&](std::size_t o) { found = found || face_of[o] == static_cast<int>(other); });
      if (found) return true;
    }
    return false;
  }

  // Each block's window: its points and its patch neighbours' within one cell.
  std::vector<Window> windows() const {
    std::vector<Window> windows(blocks_.size());
    for (std::size_t b = 0; b < blocks_.size(); ++b) {
      PointMoments points;
      forNeighbours(b, [&](std::size_t o) { points.add(stats_[o], centres_[o]); });
      if (points.count < kWindowPoints) continue;
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
      solver.computeDirect(points.covariance());
      if (solver.eigenvalues()(1) < std::pow(kWindowSpreadCells * grid_.cellSize(), 2)) continue;
      Eigen::Vector3d normal = solver.eigenvectors().col(0);
      if (normal.dot(plane_.normal) < 0.0) normal = -normal;
      windows[b] = {normal, std::sqrt(std::max(0.0, solver.eigenvalues()(0))), true};
    }
    return windows;
  }

  // Faces grown from the flattest windows over neighbours whose windows turn less than
  // κ / 3 (8.3°) from the face's mean: between the cinder faces' 13° and what one surface's
  // windows turn by where it is warped or layered (room_scan2's wall x-2.55: pieces 0.5-5°
  // apart; office1's far wall: layers 1.8° apart). And from the seed's window: the mean
  // alone drifts across a crease at 10 cm cells, where each window turns a little from
  // the last.
  std::vector<Face> grownFaces(const std::vector<Window>& windows) const {
    std::vector<std::size_t> order;
    for (std::size_t b = 0; b < blocks_.size(); ++b)
      if (windows[b].valid) order.push_back(b);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return windows[a].rms < windows[b].rms; });
    std::vector<int> face_of(blocks_.size(), -1);
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
          if (face_of[o] >= 0 || !windows[o].valid || angleBetween(windows[o].normal, mean) > grow_ ||
              angleBetween(windows[o].normal, windows[seed].normal) > grow_)
            return;
          face_of[o] = id;
          sum += windows[o].normal;
          queue.push_back(o);
        });
      }
      faces.push_back(std::move(face));
    }
    return faces;
  }

  // The blocks a face grown from windows needs to seed a face: those inside the smallest
  // face allowed (kFaceShare of the minimum area, as a square) without its rim a cell wide,
  // whose windows straddle its creases; at least kSeedFaceBlocks (2 x 2) to spread both
  // ways. 12 blocks at 5 cm cells, 4 at 10 cm, where a 0.4 m cinder face is four cells
  // across and its windows' faces hold 4-9 blocks.
  double seedBlocks() const {
    const double cell = grid_.cellSize();
    const double inside = std::max(0.0, std::sqrt(kFaceShare * config_.min_area) - 2.0 * cell) / cell;
    return std::max(static_cast<double>(kSeedFaceBlocks), inside * inside);
  }

  bool tooSmall(const std::vector<std::size_t>& members) const {
    return tooSmallForFace(members.size(), surfaceOf(members), grid_.cellSize(), config_);
  }

  // The faces large enough, fitted to their own blocks' points.
  std::vector<Face> largeFaces(std::vector<Face> faces) const {
    std::vector<Face> large;
    for (Face& face : faces) {
      if (static_cast<double>(face.members.size()) < seedBlocks()) continue;
      for (const std::size_t b : face.members) face.points.add(stats_[b], centres_[b]);
      // Its points spread across the face both ways (a row of blocks along one scan line
      // fits any plane through the line) ...
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
      solver.computeDirect(face.points.covariance());
      if (solver.eigenvalues()(1) < std::pow(kFaceSpreadCells * grid_.cellSize(), 2)) continue;
      // ... and off its plane by about the noise: points of one or two scan lines lie in the
      // scanner's sweep plane whatever the surface (room_scan2's wall x-2.55 at 5 cm: 12
      // points, RMS 0, 61° off the wall).
      if (solver.eigenvalues()(0) < std::pow(config_.noise / 3.0, 2)) continue;
      fitFace(face);
      large.push_back(std::move(face));
    }
    return large;
  }

  // Faces whose planes turn less than a window may are one: touching (a surface that
  // bends or warps, a scanner's distortion, rather than creases) or on one plane (a face
  // cut in two by a crease's windows).
  void mergeTouchingOrCoplanar(std::vector<Face>& faces) const {
    std::vector<int> face_of(blocks_.size(), -1);
    for (std::size_t f = 0; f < faces.size(); ++f)
      for (const std::size_t b : faces[f].members) face_of[b] = static_cast<int>(f);
    for (std::size_t a = 0; a < faces.size(); ++a) {
      for (std::size_t b = a + 1; b < faces.size();) {
        const bool coplanar = std::abs(faces[a].normal.dot(faces[b].point - faces[a].point)) <= config_.epsilon &&
                              std::abs(faces[b].normal.dot(faces[a].point - faces[b].point)) <= config_.epsilon;
        if (angleBetween(faces[a].normal, faces[b].normal) > grow_ ||
            !(coplanar || touches(faces[a].members, face_of, b))) {
          ++b;
          continue;
        }
        for (const std::size_t m : faces[b].members) face_of[m] = static_cast<int>(a);
        faces[a].points.merge(faces[b].points);
        faces[a].members.insert(faces[a].members.end(), faces[b].members.begin(), faces[b].members.end());
        fitFace(faces[a]);
        faces.erase(faces.begin() + static_cast<std::ptrdiff_t>(b));
        for (int& f : face_of)
          if (f > static_cast<int>(b)) --f;
        b = a + 1;
      }
    }
  }

  // Every block to the face its points lie nearest (`members`, and per face its members'
  // points' squared residuals). A face left with less than a face needs (a rim's windows,
  // a corner, a depth camera's clutter) gives its blocks to the others; faces that then
  // touch and turn less than a window may are one surface in layers or warped (a depth
  // camera's wall: two layers 16 cm apart that the windows had kept apart), fitted to the
  // blocks both took.
  void assign(std::vector<Face>& faces, std::vector<std::vector<std::size_t>>& members,
              std::vector<double>& squared) const {
    int rounds = 0;
    std::vector<std::vector<bool>> reach = reaches(faces);  // from the blocks each face grew from
    while (faces.size() >= 2) {
      members.assign(faces.size(), {});
      squared.assign(faces.size(), 0.0);
      for (std::size_t b = 0; b < blocks_.size(); ++b) {
        if (stats_[b].empty()) continue;
        std::size_t best = 0;
        double best_squared = std::numeric_limits<double>::infinity();
        bool reached = false;
        for (std::size_t f = 0; f < faces.size(); ++f) reached = reached || reach[f][b];
        for (std::size_t f = 0; f < faces.size(); ++f) {
          if (reached && !reach[f][b]) continue;
          const double mean_squared = meanSquared(stats_[b], centres_[b], faces[f].normal, faces[f].point);
          if (mean_squared < best_squared) best = f, best_squared = mean_squared;
        }
        // A block whose points lie off every face by more than 3 σ (RMS) is on none: a
        // cinder block's side, a crease's cell at 10 cm (neither counts for or against).
        if (best_squared > std::pow(3.0 * config_.noise, 2)) continue;
        members[best].push_back(b);
        squared[best] += stats_[b].count * best_squared;
      }
      // The smallest of the faces too small.
      std::size_t smallest = faces.size();
      for (std::size_t f = 0; f < faces.size(); ++f) {
        if (tooSmall(members[f]) && (smallest == faces.size() || surfaceOf(members[f]) < surfaceOf(members[smallest])))
          smallest = f;
      }
      if (smallest < faces.size()) {
        faces.erase(faces.begin() + static_cast<std::ptrdiff_t>(smallest));
        reach.erase(reach.begin() + static_cast<std::ptrdiff_t>(smallest));
        continue;
      }
      // Each face refitted to the blocks it took, until they stay the same: a face grown
      // from windows leans towards its neighbours where its rim's windows straddled their
      // crease (a level cinder face 7° off at 10 cm cells), and then took their near blocks.
      bool moved = false;
      for (std::size_t f = 0; f < faces.size(); ++f) {
        std::sort(faces[f].members.begin(), faces[f].members.end());
        if (faces[f].members == members[f]) continue;
        moved = true;
        faces[f].members = members[f];
        refit(faces[f]);
      }
      if (moved && ++rounds < kAssignRounds) continue;
      const std::vector<int> face_of = faceOfBlocks(members);
      bool merged = false;
      for (std::size_t a = 0; a < faces.size() && !merged; ++a) {
        for (std::size_t b = a + 1; b < faces.size() && !merged; ++b) {
          if (angleBetween(faces[a].normal, faces[b].normal) > grow_ || !touches(members[a], face_of, b)) continue;
          // Both faces' members are the blocks they took (members) once the rounds end.
          faces[a].members.insert(faces[a].members.end(), faces[b].members.begin(), faces[b].members.end());
          refit(faces[a]);
          faces.erase(faces.begin() + static_cast<std::ptrdiff_t>(b));
          for (std::size_t k = 0; k < blocks_.size(); ++k) reach[a][k] = reach[a][k] || reach[b][k];
          reach.erase(reach.begin() + static_cast<std::ptrdiff_t>(b));
          merged = true;
        }
      }
      if (!merged) break;
    }
  }

  // A face's plane refitted to its members' points.
  void refit(Face& face) const {
    face.points = PointMoments{};
    for (const std::size_t m : face.members) face.points.add(stats_[m], centres_[m]);
    fitFace(face);
  }

  // Per face, the blocks within kReachSteps neighbour steps of the blocks it grew from: a
  // block goes to a face near it, not to the extension of a face's plane across the patch
  // (plane_seg's cinder blocks at 10 cm cells turned 40°: a level face's plane passes
  // through the tilted faces beside it at their mid-height, and took half of them). A
  // block no face reaches goes to the nearest plane, as all did before.
  std::vector<std::vector<bool>> reaches(const std::vector<Face>& faces) const {
    std::vector<std::vector<bool>> reach(faces.size(), std::vector<bool>(blocks_.size(), false));
    for (std::size_t f = 0; f < faces.size(); ++f) {
      std::vector<std::size_t> ring = faces[f].members;
      for (const std::size_t b : ring) reach[f][b] = true;
      for (int step = 0; step < kReachSteps; ++step) {
        std::vector<std::size_t> next;
        for (const std::size_t b : ring)
          forNeighbours(b, [&](std::size_t o) {
            if (!reach[f][o]) reach[f][o] = true, next.push_back(o);
          });
        ring = std::move(next);
      }
    }
    return reach;
  }

  std::vector<int> faceOfBlocks(const std::vector<std::vector<std::size_t>>& members) const {
    std::vector<int> face_of(blocks_.size(), -1);
    for (std::size_t f = 0; f < members.size(); ++f)
      for (const std::size_t b : members[f]) face_of[b] = static_cast<int>(f);
    return face_of;
  }

  // A crease: two touching faces that turn more than a window may. Faces all within that
  // of each other are parallel layers or one warped surface, not creased (room_scan2's
  // wall x-2.55, warped by ±10 cm: pieces 0.5-5° apart and 5-10 cm off each other).
  bool creased(const std::vector<Face>& faces, const std::vector<std::vector<std::size_t>>& members) const {
    const std::vector<int> face_of = faceOfBlocks(members);
    for (std::size_t a = 0; a < faces.size(); ++a)
      for (std::size_t b = a + 1; b < faces.size(); ++b)
        if (angleBetween(faces[a].normal, faces[b].normal) > grow_ && touches(members[a], face_of, b)) return true;
    return false;
  }

  // The split stands when the faces' squared residuals are at most a quarter of the one
  // plane's over the same blocks, and the faces hold most of the patch's points: where over
  // 15 % lie off every face (a depth camera's layered wall: 34 %; ANYmal's treads and risers
  // of a 2 cm elevation map: 24 %) the faces are not what the patch is made of (the cinder
  // blocks at 10 cm cells: 10 %, at 5 cm 2.5 %).
  bool explained(const std::vector<std::vector<std::size_t>>& members, const std::vector<double>& squared) const {
    double one = 0.0;
    double on_faces = 0.0;
    for (const std::vector<std::size_t>& face : members) {
      for (const std::size_t b : face) {
        one += stats_[b].count * meanSquared(stats_[b], centres_[b], plane_.normal, patch_point_);
        on_faces += stats_[b].count;
      }
    }
    const double split = std::accumulate(squared.begin(), squared.end(), 0.0);
    if (!(split <= kSplitGain * one)) return false;
    double all = 0.0;
    for (const PointStats& stats : stats_) all += stats.count;
    return on_faces >= (1.0 - kOffFaces) * all;
  }

  const BlockGrid& grid_;
  const PatchSet& set_;
  const std::vector<std::uint32_t>& blocks_;
  const Plane& plane_;
  std::int32_t label_;
  const CreaseConfig& config_;
  double grow_;
  std::vector<PointStats> stats_;
  std::vector<Eigen::Vector3d> centres_;  // the blocks' point-stats frames, about the patch's centroid
  std::unordered_map<std::uint32_t, std::size_t> index_;  // block id -> index here
  Eigen::Vector3d patch_point_;  // a point on the patch's plane, about its centroid
};

}  // namespace

bool tooSmallForFace(std::size_t blocks, double surface, double cell_size, const CreaseConfig& config) {
  return blocks < static_cast<std::size_t>(config.min_blocks) ||
         surface * cell_size * cell_size < kFaceShare * config.min_area;
}

std::vector<std::vector<std::size_t>> creaseFaces(const BlockGrid& grid, const PatchSet& set, std::size_t k,
                                                  const CreaseConfig& config) {
  return PatchFaces(grid, set, k, config).find();
}

}  // namespace mlmap
