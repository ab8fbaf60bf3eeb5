#include "mlmap/planes/classify.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <vector>

namespace mlmap {
namespace {

struct Extent {
  Eigen::Vector3d min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d max = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
};

Extent extentOf(const Plane& plane) {
  Extent extent;
  for (const Eigen::Vector3d& p : plane.outline) {
    extent.min = extent.min.cwiseMin(p);
    extent.max = extent.max.cwiseMax(p);
  }
  if (plane.outline.empty()) extent.min = extent.max = plane.centroid;
  return extent;
}

// A wall: plumb and at least wall_min_height tall, over all its pieces (Plane::bounds: a wall
// seen between furniture is one patch of several pieces, its outline round the largest),
// unless its largest piece is no taller than a riser: a riser's patch with a few cells of the
// flight's higher risers in its plane (fr079 at 10 cm turned 10-25° to the grid: pieces
// 0.9-1.1 m apart in z round a 0.2 m riser).
bool isWall(const Plane& plane, const Extent& extent, const ClassifyConfig& config) {
  const double largest_piece = extent.max.z() - extent.min.z();
  const double all_pieces =
      plane.bounds.isEmpty() ? largest_piece : std::max(largest_piece, plane.bounds.sizes().z());
  return isPlumb(plane.normal, config) &&
         (largest_piece >= config.wall_min_height ||
          (all_pieces >= config.wall_min_height && largest_piece > config.riser_max + config.level_tolerance));
}

// The height where walls end below, where two or more end together (within level_tolerance):
// the lowest such foot, their mean. None where no two walls agree.
std::optional<double> sharedWallFoot(const std::vector<Plane>& planes, const std::vector<Extent>& extents,
                                     const ClassifyConfig& config) {
  std::vector<double> feet;
  for (std::size_t k = 0; k < planes.size(); ++k) {
    if (!isWall(planes[k], extents[k], config)) continue;
    const double foot = extents[k].min.z();
    feet.push_back(planes[k].bounds.isEmpty() ? foot : std::min(foot, planes[k].bounds.min().z()));
  }
  std::sort(feet.begin(), feet.end());
  for (std::size_t k = 0; k + 1 < feet.size(); ++k) {
    std::size_t end = k + 1;
    while (end < feet.size() && feet[end] - feet[k] <= config.level_tolerance) ++end;
    if (end - k < 2) continue;
    const auto first = feet.begin() + static_cast<std::ptrdiff_t>(k);
    return std::accumulate(first, feet.begin() + static_cast<std::ptrdiff_t>(end), 0.0) / static_cast<double>(end - k);
  }
  return std::nullopt;
}

// An outline seen from above, as edges (a, b) in x and y.
struct OutlineEdge {
  Eigen::Vector2d a, b;
};

std::vector<OutlineEdge> edgesOf(const std::vector<Eigen::Vector3d>& outline) {
  std::vector<OutlineEdge> edges;
  edges.reserve(outline.size());
  for (std::size_t k = 0, previous = outline.size() - 1; k < outline.size(); previous = k++) {
    edges.push_back({outline[k].head<2>(), outline[previous].head<2>()});
  }
  return edges;
}

// The edges that can decide, on the row at y, whether a point lies inside (they cross the
// row) or within `depth` of the boundary: the others lie more than `depth` away in y alone.
void edgesNearRow(const std::vector<OutlineEdge>& edges, double y, double depth, std::vector<OutlineEdge>& near) {
  near.clear();
  for (const OutlineEdge& edge : edges) {
    if (std::min(edge.a.y(), edge.b.y()) - depth <= y && y <= std::max(edge.a.y(), edge.b.y()) + depth) {
      near.push_back(edge);
    }
  }
}

// Whether (x, y) lies inside the outline seen from above (even-odd rule) at least `depth`
// from its boundary, given the row's edges from edgesNearRow.
bool deepInside(const std::vector<OutlineEdge>& near, double x, double y, double depth) {
  bool inside = false;
  double nearest = std::numeric_limits<double>::infinity();
  const Eigen::Vector2d p(x, y);
  for (const OutlineEdge& e : near) {
    const Eigen::Vector2d &a = e.a, &b = e.b;
    if ((a.y() > y) != (b.y() > y) && x < a.x() + (y - a.y()) * (b.x() - a.x()) / (b.y() - a.y())) inside = !inside;
    const Eigen::Vector2d edge = b - a;
    const double t = edge.squaredNorm() > 0.0 ? std::clamp((p - a).dot(edge) / edge.squaredNorm(), 0.0, 1.0) : 0.0;
    nearest = std::min(nearest, (p - a - t * edge).norm());
  }
  return inside && nearest >= depth;
}

// The share of the smaller of two patches that lies over (or under) the other deeper
// than `depth` inside both outlines seen from above, sampled on a grid of at most
// kOverlapSamples points.
constexpr double kOverlapSamples = 20000.0;
double deepOverlapShare(const Plane& a, const Plane& b, const Extent& extent_a, const Extent& extent_b,
                        double depth) {
  if (a.outline.size() < 3 || b.outline.size() < 3) return 0.0;
  const double x0 = std::max(extent_a.min.x(), extent_b.min.x()) + depth;
  const double x1 = std::min(extent_a.max.x(), extent_b.max.x()) - depth;
  const double y0 = std::max(extent_a.min.y(), extent_b.min.y()) + depth;
  const double y1 = std::min(extent_a.max.y(), extent_b.max.y()) - depth;
  const double smaller = std::min(a.area, b.area);
  if (!(x1 > x0 && y1 > y0 && smaller > 0.0)) return 0.0;
  const double step = std::max(0.01, std::sqrt((x1 - x0) * (y1 - y0) / kOverlapSamples));
  const std::vector<OutlineEdge> edges_a = edgesOf(a.outline), edges_b = edgesOf(b.outline);
  std::vector<OutlineEdge> near_a, near_b;
  std::size_t both = 0;
  // Row by row (y outer): each row tests a point against the few edges near it.
  for (double y = y0 + 0.5 * step; y < y1; y += step) {
    edgesNearRow(edges_a, y, depth, near_a);
    edgesNearRow(edges_b, y, depth, near_b);
    for (double x = x0 + 0.5 * step; x < x1; x += step) {
      if (deepInside(near_a, x, y, depth) && deepInside(near_b, x, y, depth)) ++both;
    }
  }
  return static_cast<double>(both) * step * step / smaller;
}

bool neighbours(const Extent& a, const Extent& b, double gap) {
  return a.min.x() - gap <= b.max.x() && b.min.x() - gap <= a.max.x() &&
         a.min.y() - gap <= b.max.y() && b.min.y() - gap <= a.max.y();
}

}  // namespace

std::string_view className(PlaneClass plane_class) {
  switch (plane_class) {
    case PlaneClass::Floor: return "floor";
    case PlaneClass::Ceiling: return "ceiling";
    case PlaneClass::Wall: return "wall";
    case PlaneClass::Table: return "table";
    case PlaneClass::Step: return "step";
    case PlaneClass::Other: break;
  }
  return "other";
}

HeightReference classifyPlanes(std::vector<Plane>& planes, const ClassifyConfig& config,
                               std::span<const SurfaceSample> surface, std::vector<std::uint8_t>* landings) {
  if (landings != nullptr) landings->assign(planes.size(), 0);
  std::vector<std::size_t> horizontal;
  std::vector<Extent> extents;
  for (std::size_t k = 0; k < planes.size(); ++k) {
    extents.push_back(extentOf(planes[k]));
    if (isLevel(planes[k].normal, config)) horizontal.push_back(k);
  }
  // The floor: the largest horizontal patch among the lowest ones; the ceiling: the
  // largest one a storey above it. Heights are taken from the floor's plane, not as z:
  // real scans are seldom level (3DTK's floor 4° off in its registered frame, PCL's
  // room_scan2 2°), and across a room of 5 m two patches of one such floor differ by
  // 8-35 cm in z at their centroids.
  // "The lowest" is measured from each candidate's own plane too: in a frame turned a few
  // degrees off level, z at the centroids of one floor's patches differs by more than the
  // search reaches (3DTK's corridor at 0.2 m cells, 2.9° off: a rough 2 m² patch at its far
  // end lay 0.55 m lower in z than the floor's 20 m² patch, 0.33 m below the floor's plane,
  // and the floor came out 'other').
  // The largest horizontal patch that `qualifies` (the first of equals), or none.
  const auto largestWhere = [&](const auto& qualifies) {
    const Plane* largest = nullptr;
    for (const std::size_t k : horizontal) {
      if ((largest == nullptr || planes[k].area > largest->area) && qualifies(planes[k])) largest = &planes[k];
    }
    return largest;
  };
  const Plane* floor = largestWhere([&](const Plane& candidate) {
    return std::all_of(horizontal.begin(), horizontal.end(), [&](std::size_t other) {
      return candidate.normal.dot(planes[other].centroid) + candidate.offset >= -config.floor_search;
    });
  });
  // Where every candidate's plane (up to 15° off level) puts another patch far below it, the
  // lowest in z, as before.
  if (floor == nullptr) {
    double lowest = std::numeric_limits<double>::infinity();
    for (const std::size_t k : horizontal) lowest = std::min(lowest, planes[k].centroid.z());
    floor = largestWhere([&](const Plane& candidate) { return candidate.centroid.z() <= lowest + config.floor_search; });
  }
  const Plane* ceiling = nullptr;
  // Nothing lies under a floor.
  const auto nothingBelow = [&](const Plane& level) {
    double below = 0.0, total = 0.0;
    for (const SurfaceSample& sample : surface) {
      total += sample.weight;
      if (level.normal.dot(sample.point) + level.offset < -config.riser_max) below += sample.weight;
    }
    return below <= config.floor_max_share_below * total;
  };
  if (floor != nullptr && !nothingBelow(*floor)) floor = nullptr;
  // Without a floor in view, heights are measured from where the walls end below: a cloud
  // cut above its floor (Bobkov's room 2: its three walls end at z 1.50, its table top 0.68 m
  // and its sideboard 0.47 m over that, and they were 'other'). No patch is floor then, and
  // no flight climbs from it.
  Plane walls_foot;
  const Plane* reference = floor;
  if (floor == nullptr) {
    if (const std::optional<double> foot = sharedWallFoot(planes, extents, config)) {
      walls_foot.normal = Eigen::Vector3d::UnitZ();
      walls_foot.offset = -*foot;
      if (nothingBelow(walls_foot)) reference = &walls_foot;
    }
  }
  // m: how far `point` lies above the floor's plane (horizontal normals point up).
  auto aboveFloor = [&](const Eigen::Vector3d& point) { return reference->normal.dot(point) + reference->offset; };
  for (const std::size_t k : horizontal) {
    if (reference != nullptr && aboveFloor(planes[k].centroid) >= config.ceiling_min_height &&
        (ceiling == nullptr || planes[k].area > ceiling->area)) {
      ceiling = &planes[k];
    }
  }
  auto near = [&](const Plane* level, const Eigen::Vector3d& point) {
    return level != nullptr && std::abs(level->normal.dot(point) + level->offset) < config.level_tolerance;
  };
  // Horizontal patches first: risers and steps refer to them.
  for (const std::size_t k : horizontal) {
    if (near(floor, planes[k].centroid)) {
      planes[k].label = PlaneClass::Floor;
    } else if (near(ceiling, planes[k].centroid)) {
      planes[k].label = PlaneClass::Ceiling;
    } else {
      planes[k].label = PlaneClass::Other;
    }
  }
  // Two level patches a riser apart, side by side: consecutive steps (or a step and the
  // floor). Side by side, not one over the other: a tread's outline overlaps the next one's
  // in a strip along the riser, as wide as the outlines round out to cells; a chair's seat
  // lies under the table (Bobkov's room 2 at 10 cm: the seats' patch under the table top,
  // a riser below it, made the table, the seats and the sideboard a flight of steps).
  auto oneStepApart = [&](std::size_t a, std::size_t b) {
    const double rise = std::abs(planes[a].centroid.z() - planes[b].centroid.z());
    return a != b && rise >= config.riser_min && rise <= config.riser_max &&
           neighbours(extents[a], extents[b], config.neighbour_gap) &&
           (planes[a].label == PlaneClass::Floor || planes[b].label == PlaneClass::Floor ||
            deepOverlapShare(planes[a], planes[b], extents[a], extents[b], config.step_overlap_depth) <=
                config.max_step_overlap);
  };
  auto belowCeiling = [&](const Plane& plane) {
    return ceiling == nullptr || ceiling->normal.dot(plane.centroid) + ceiling->offset < -config.riser_max;
  };
  // With a floor in view, a step is one of a flight that climbs from it (or descends to
  // it), riser by riser: a desk top beside a chair seat, a keyboard shelf or a drawer
  // one riser below it is furniture, not a staircase. PCL's two room scans put four desk
  // tops (0.7 m above the floor) a riser from such a piece, and all were steps. Without a
  // floor, a flight is three level patches or more, each a riser from the next: a table
  // top and the one piece a riser below it are no staircase (Bobkov's room 2, a cloud cut
  // above its floor: its table and sideboard tops were steps).
  // Tilted patches low enough for one step's band (a tread and its riser, or a riser and its
  // nosing, in one patch: stepped.hpp cuts a ramp through a flight into these).
  std::vector<std::size_t> bands;
  for (std::size_t k = 0; k < planes.size(); ++k) {
    if (!isLevel(planes[k].normal, config) && !isPlumb(planes[k].normal, config) &&
        extents[k].max.z() - extents[k].min.z() <= config.riser_max + config.level_tolerance)
      bands.push_back(k);
  }
  // What a flight that climbs from the floor may hold: the level patches and, between them,
  // such bands. plane_seg's ANYmal stairs at 10 cm cells: the second tread's patch leans 16.5°
  // (it holds the riser below it), and the flight from the floor stopped there, so the third
  // tread (0.5 m over the floor) and the upper landing read as tables.
  std::vector<std::size_t> steppable = horizontal;
  steppable.insert(steppable.end(), bands.begin(), bands.end());
  auto mayStep = [&](std::size_t k) {
    return (planes[k].label == PlaneClass::Other || !isLevel(planes[k].normal, config)) && belowCeiling(planes[k]);
  };
  std::vector<std::uint8_t> step(planes.size(), 0);  // 1: a step; 3: a landing; 0 and 2: not
  // Grows a flight from `members` (marked in `step` already) through riser links to `candidates`.
  auto grow = [&](std::vector<std::size_t>& members, const std::vector<std::size_t>& candidates) {
    for (std::size_t n = 0; n < members.size(); ++n) {
      for (const std::size_t k : candidates) {
        if (step[k] == 0 && mayStep(k) && oneStepApart(k, members[n])) {
          step[k] = 1;
          members.push_back(k);
        }
      }
    }
  };
  // The flight's landings (step 3): level steps far larger than its treads (landing_min_*).
  auto markLandings = [&](const std::vector<std::size_t>& flight) {
    std::vector<std::size_t> level;
    for (const std::size_t k : flight)
      if (isLevel(planes[k].normal, config)) level.push_back(k);
    if (level.size() < 2) return;
    for (const std::size_t k : level) {
      if (planes[k].area < config.landing_min_area) continue;
      std::vector<double> others;
      for (const std::size_t o : level)
        if (o != k) others.push_back(planes[o].area);
      std::nth_element(others.begin(), others.begin() + static_cast<std::ptrdiff_t>(others.size() / 2), others.end());
      if (planes[k].area >= config.landing_min_treads * others[others.size() / 2]) step[k] = 3;
    }
  };
  if (floor != nullptr) {
    std::vector<std::size_t> flight;
    for (const std::size_t k : steppable) {
      if (!mayStep(k)) continue;
      for (const std::size_t other : horizontal) {
        if (planes[other].label == PlaneClass::Floor && oneStepApart(k, other)) {
          step[k] = 1;
          flight.push_back(k);
          break;
        }
      }
    }
    grow(flight, steppable);
    markLandings(flight);
  } else {
    // Without a floor, level patches only: a band between a table and a seat would make
    // three (Bobkov's room 2 at 10 cm cells: its table and sideboard tops became steps).
    for (const std::size_t k : horizontal) {
      if (step[k] != 0 || !mayStep(k)) continue;
      std::vector<std::size_t> flight{k};
      step[k] = 1;
      grow(flight, horizontal);
      // Too short a flight: seen (2), so no later one grows into it, and no step.
      if (flight.size() < 3) {
        for (const std::size_t member : flight) step[member] = 2;
      }
    }
  }
  for (const std::size_t k : horizontal) {
    Plane& plane = planes[k];
    if (plane.label != PlaneClass::Other) continue;
    const double above_floor = reference != nullptr ? aboveFloor(plane.centroid) : 0.0;
    if (step[k] == 3) {
      plane.label = PlaneClass::Floor;
      if (landings != nullptr) (*landings)[k] = 1;
    } else if (step[k] == 1) {
      plane.label = PlaneClass::Step;
    } else if (reference != nullptr && above_floor >= config.table_min_height &&
               above_floor <= config.table_max_height) {
      plane.label = PlaneClass::Table;
    }
  }
  // Bands a riser apart and side by side, three or more, are a flight too: one seen from
  // below, each step its riser and nosing. Its risers, where a patch holds one alone (a
  // plumb patch no taller than a band), are steps of it too: OctoMap's fr079 at 10 cm
  // cells, whose lower steps seen from below came as risers 20 cm tall beside the bands
  // of the upper ones, and were 'other'. A riser is a going from the next step, not over
  // it: drawer fronts stacked in one plane are no flight.
  const auto riser = [&](std::size_t k) {
    return isPlumb(planes[k].normal, config) &&
           extents[k].max.z() - extents[k].min.z() <= config.riser_max + config.level_tolerance;
  };
  std::vector<std::size_t> below = bands;
  for (std::size_t k = 0; k < planes.size(); ++k)
    if (riser(k)) below.push_back(k);
  const auto goingApart = [&](std::size_t a, std::size_t b) {
    return !(riser(a) || riser(b)) ||
           (planes[a].centroid - planes[b].centroid).head<2>().norm() >= config.min_going;
  };
  std::vector<std::uint8_t> in_flight(planes.size(), 0);
  for (const std::size_t start : below) {
    if (in_flight[start] != 0) continue;
    std::vector<std::size_t> flight{start};
    in_flight[start] = 2;
    for (std::size_t n = 0; n < flight.size(); ++n) {
      for (const std::size_t k : below) {
        const double rise = std::abs(planes[k].centroid.z() - planes[flight[n]].centroid.z());
        if (in_flight[k] == 0 && rise >= config.riser_min && rise <= config.riser_max &&
            neighbours(extents[k], extents[flight[n]], config.neighbour_gap) && goingApart(k, flight[n])) {
          in_flight[k] = 2;
          flight.push_back(k);
        }
      }
    }
    if (flight.size() >= 3)
      for (const std::size_t member : flight) in_flight[member] = 1;
  }
  for (std::size_t k = 0; k < planes.size(); ++k) {
    Plane& plane = planes[k];
    if (isLevel(plane.normal, config)) continue;
    if (!isPlumb(plane.normal, config)) {
      plane.label = in_flight[k] == 1 || step[k] == 1 ? PlaneClass::Step : PlaneClass::Other;
      continue;
    }
    const double height = extents[k].max.z() - extents[k].min.z();
    if (isWall(plane, extents[k], config)) {
      plane.label = PlaneClass::Wall;
      continue;
    }
    // A riser: low, between a step and the floor or another step, or of a flight seen from below.
    plane.label = in_flight[k] == 1 ? PlaneClass::Step : PlaneClass::Other;
    if (height <= config.riser_max + config.level_tolerance) {
      for (const std::size_t other : horizontal) {
        if ((planes[other].label == PlaneClass::Step || step[other] == 3) &&
            std::abs(planes[other].centroid.z() - extents[k].max.z()) < config.level_tolerance + 0.05 &&
            neighbours(extents[k], extents[other], config.neighbour_gap)) {
          plane.label = PlaneClass::Step;
        }
      }
    }
  }
  if (floor != nullptr) return {HeightReference::Kind::Floor, 0.0};
  if (reference != nullptr) return {HeightReference::Kind::WallsFoot, -walls_foot.offset};
  return {};
}

// PCL's room_scan1 at 5 cm cells: the next room's ceiling, 14.9 m² 4-5 m from the
// ceiling's centroid, lies 9 cm below the ceiling's plane there (the two planes lean 1.2°
// apart in a scan that is not quite flat) and was 'other'; room_scan2 at 10 cm: 8.75 m².
// Labelled so before the level merge, such pieces joined the ceiling and leaned its plane.
void labelCeilingPieces(std::vector<Plane>& planes, const ClassifyConfig& config, std::span<const std::uint8_t> landings) {
  const Plane* floor = nullptr;
  const Plane* ceiling = nullptr;
  for (std::size_t k = 0; k < planes.size(); ++k) {
    const Plane& plane = planes[k];
    const bool landing = k < landings.size() && landings[k] != 0;
    if (plane.label == PlaneClass::Floor && !landing && (floor == nullptr || plane.area > floor->area)) floor = &plane;
    if (plane.label == PlaneClass::Ceiling && (ceiling == nullptr || plane.area > ceiling->area)) ceiling = &plane;
  }
  if (floor == nullptr || ceiling == nullptr) return;
  // Only the other patches' labels change below: the floor and the ceiling stay as they are.
  for (Plane& plane : planes) {
    if (plane.label == PlaneClass::Floor || plane.label == PlaneClass::Ceiling) continue;
    if (!isLevel(plane.normal, config)) continue;
    if (floor->normal.dot(plane.centroid) + floor->offset >= config.ceiling_min_height &&
        std::abs(ceiling->normal.dot(plane.centroid) + ceiling->offset) < config.riser_max) {
      plane.label = PlaneClass::Ceiling;
    }
  }
}

}  // namespace mlmap
