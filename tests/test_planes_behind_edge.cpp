// behindEdge: a point past a surface's plane, seen from its scanner, is that surface's
// noise, not a point of a patch that ends at the plane.
#include <doctest/doctest.h>

#include <vector>

#include "../src/planes/edge_choice.hpp"

using namespace mlmap;

namespace {

// Slot 1: a wall x = 0 seen from x > 0; slot 2: a cabinet's side y = 1 standing against
// it, x 0-0.5. Tolerances 3 cm (σ 1 cm); the beams' range noise unknown (infinite).
struct Corner {
  std::vector<PointPlane> fitted = std::vector<PointPlane>(3);
  std::vector<Eigen::Vector3d> wall_outline{{0, 0, 0}, {0, 5, 0}, {0, 5, 2.8}, {0, 0, 2.8}};
  std::vector<Eigen::Vector3d> side_outline{{0, 1, 0}, {0.5, 1, 0}, {0.5, 1, 1.8}, {0, 1, 1.8}};
  std::vector<double> along = std::vector<double>(3, std::numeric_limits<double>::infinity());
  std::vector<std::int8_t> seen_from{0, 1, -1};  // the wall from x > 0, the side from y < 1
  Point scanner{2.0, 0.0, 1.2};

  Corner() {
    fitted[1] = PointPlane{1, Eigen::Vector3d::UnitX(), 0.0, 0.03, 100000};
    fitted[2] = PointPlane{2, Eigen::Vector3d::UnitY(), -1.0, 0.03, 5000};
  }
  std::uint32_t choose(const Point& point) const {
    const OutlineReach reach({nullptr, &wall_outline, &side_outline}, fitted, 0.1);
    const std::vector<Candidate> candidates{{1, 0.0, 0.0}, {2, 0.0, 0.0}};
    return behindEdge(2, point, &scanner, candidates, fitted, along, seen_from, reach, 0.05, 2.0);
  }
};

}  // namespace

TEST_CASE("behindEdge: a wall's point behind it, on a cabinet side's plane, is the wall's") {
  Corner corner;
  // 4 σ behind the wall (past its tolerance): the side, ending at the wall, had it.
  CHECK(corner.choose({-0.04, 1.005, 1.0}) == 1);
  CHECK(corner.choose({-0.02, 0.995, 0.4}) == 1);
  // In front of the wall the choice stays the side's (likeliest decides there).
  CHECK(corner.choose({0.04, 1.005, 1.0}) == 2);
  // Beyond the wall's noise tail (6 σ): something seen through, not the wall.
  CHECK(corner.choose({-0.07, 1.0, 1.0}) == 2);
}

TEST_CASE("behindEdge: in a cloud without scanners, a floor's point below it is the floor's") {
  // A box's side x = 1 (x 1-1.5, z 0-0.5) on the floor z = 0, seen from above (a floor
  // by its class); no scanner positions.
  std::vector<PointPlane> fitted(3);
  fitted[1] = PointPlane{1, Eigen::Vector3d::UnitZ(), 0.0, 0.03, 100000};
  fitted[2] = PointPlane{2, Eigen::Vector3d::UnitX(), -1.0, 0.03, 3000};
  Plane floor;
  floor.label = PlaneClass::Floor;
  Plane side;
  side.label = PlaneClass::Other;
  const std::vector<std::int8_t> seen_from{0, levelSeenFrom(floor, fitted[1]), levelSeenFrom(side, fitted[2])};
  CHECK(seen_from[1] == 1);
  CHECK(seen_from[2] == 0);
  const std::vector<Eigen::Vector3d> floor_outline{{0, 0, 0}, {5, 0, 0}, {5, 5, 0}, {0, 5, 0}};
  const std::vector<Eigen::Vector3d> side_outline{{1, 1, 0}, {1, 1.5, 0}, {1, 1.5, 0.5}, {1, 1, 0.5}};
  const OutlineReach reach({nullptr, &floor_outline, &side_outline}, fitted, 0.1);
  const std::vector<double> along(3, std::numeric_limits<double>::infinity());
  const std::vector<Candidate> candidates{{1, 0.0, 0.0}, {2, 0.0, 0.0}};
  CHECK(behindEdge(2, {1.005, 1.2, -0.04}, nullptr, candidates, fitted, along, seen_from, reach, 0.05, 2.0) == 1);
  CHECK(behindEdge(2, {1.005, 1.2, 0.04}, nullptr, candidates, fitted, along, seen_from, reach, 0.05, 2.0) == 2);
  // The side's plane decides nothing (a wall's open side is unknown without scanners).
  CHECK(behindEdge(1, {0.96, 1.2, 0.01}, nullptr, candidates, fitted, along, seen_from, reach, 0.05, 2.0) == 1);
}

TEST_CASE("behindEdge: only a larger surface, seen from its front, that the patch ends at decides") {
  Corner corner;
  const Point behind{-0.04, 1.005, 1.0};
  SUBCASE("a smaller surface") {
    corner.fitted[1].points = 4000;
    CHECK(corner.choose(behind) == 2);
  }
  SUBCASE("a surface the point's scanner sees from behind") {
    corner.seen_from[1] = -1;  // its points were seen from x < 0
    CHECK(corner.choose(behind) == 2);
  }
  SUBCASE("a patch reaching through the plane") {
    corner.side_outline[0].x() = -0.5;
    corner.side_outline[3].x() = -0.5;
    CHECK(corner.choose(behind) == 2);
  }
  SUBCASE("a scanner at no position") {
    corner.scanner = Point::Constant(std::numeric_limits<double>::quiet_NaN());
    CHECK(corner.choose(behind) == 2);
  }
  SUBCASE("parallel planes are layers, not an edge") {
    corner.fitted[2].normal = Eigen::Vector3d::UnitX();
    corner.fitted[2].offset = -0.01;
    CHECK(corner.choose(behind) == 2);
  }
}

namespace {

// nearerAlongBeam's scene: the wall x = 0 (slot 1, 100 000 points) and a cabinet's side
// y = 1 (slot 2, 5 000), both with 3 cm of range noise along their beams (3 σ); a point on
// the side's plane alone, the wall its tail candidate.
struct WallAndSide {
  std::vector<PointPlane> fitted = std::vector<PointPlane>(3);
  std::vector<double> along{0.0, 0.03, 0.03};

  WallAndSide() {
    fitted[1] = PointPlane{1, Eigen::Vector3d::UnitX(), 0.0, 0.03, 100000};
    fitted[2] = PointPlane{2, Eigen::Vector3d::UnitY(), -1.0, 0.03, 5000};
  }
  // The distance along `beam` from `point` to a slot's plane (as gather ranks it).
  double rank(std::uint32_t slot, const Point& point, const Eigen::Vector3d& beam) const {
    return std::abs(fitted[slot].normal.dot(point) + fitted[slot].offset) /
           std::max(kMinIncidenceCosine, std::abs(fitted[slot].normal.dot(beam)));
  }
  std::uint32_t choose(const Point& point, const Eigen::Vector3d& beam) const {
    const Candidate alone{2, rank(2, point, beam), 0.0};
    const std::vector<Candidate> tail{{1, rank(1, point, beam), 0.0}};
    return nearerAlongBeam(alone, tail, fitted, along, 2.0);
  }
};

}  // namespace

TEST_CASE("nearerAlongBeam: a wall's point 3 sigma in front of it, seen along a cabinet's side, is the wall's") {
  // A point 3.2 cm in front of the wall and 1.3 cm off the side's plane lies within the
  // side's tolerance alone.
  WallAndSide scene;
  const Point point{0.032, 0.987, 1.0};
  // Seen nearly along the side: its plane lies 7 cm along the beam, the wall's 3.3 cm.
  CHECK(scene.choose(point, Eigen::Vector3d(-0.97, 0.18, 0.16).normalized()) == 1);
  // Seen head on, the side's plane lies 1.3 cm along the beam: within its range noise.
  CHECK(scene.choose(point, Eigen::Vector3d(-0.3, 0.95, 0.0).normalized()) == 2);
  // A smaller surface's tail takes nothing from a larger patch.
  scene.fitted[1].points = 1000;
  CHECK(scene.choose(point, Eigen::Vector3d(-0.97, 0.18, 0.16).normalized()) == 2);
}

TEST_CASE("nearerAlongBeam: a point either surface could have returned goes to the larger, as at an edge") {
  // A point 2 cm in front of the wall and 1.3 cm off the side's plane, seen obliquely:
  // along its beam the wall's plane lies 2.7 cm off, the side's 2 cm, both within their
  // range noise. The side took it (the lab with 3 cm of range noise: single floor and wall
  // points on crates' and cabinets' patches, each such patch then touching the floor or a
  // wall it is no part of).
  WallAndSide scene;
  const Point point{0.02, 0.987, 1.0};
  const Eigen::Vector3d beam = Eigen::Vector3d(-0.75, 0.66, 0.0).normalized();
  REQUIRE(scene.rank(1, point, beam) < scene.along[1]);
  REQUIRE(scene.rank(2, point, beam) < scene.along[2]);
  CHECK(scene.choose(point, beam) == 1);
  // The smaller surface keeps what it could have returned.
  scene.fitted[1].points = 1000;
  CHECK(scene.choose(point, beam) == 2);
  // Beyond the wall's range noise along the beam (5 cm in front of it), the side keeps it.
  scene.fitted[1].points = 100000;
  const Point farther{0.05, 0.987, 1.0};
  REQUIRE(scene.rank(1, farther, beam) > scene.along[1]);
  CHECK(scene.choose(farther, beam) == 2);
}

TEST_CASE("withinRangeNoise: a plane the beam grazes is not within its range noise however near") {
  const std::vector<double> along{0.0, 0.03, 0.06};
  // The floor, 3.5 cm off along the beam: beyond its 3 cm.
  CHECK_FALSE(withinRangeNoise(Candidate{1, 0.035, 0.035}, along));
  CHECK(withinRangeNoise(Candidate{1, 0.02, 0.02}, along));
  // A face the beam grazes (|n·beam| < kMinIncidenceCosine): 2.5 cm across it is at least
  // 0.5 m along the beam, whatever `meets` (0 there) says.
  const double across = 0.025;
  CHECK_FALSE(withinRangeNoise(Candidate{2, across / kMinIncidenceCosine, 0.0}, along));
}
