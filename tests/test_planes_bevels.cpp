// Bevels (issue 19: "slanted strips along edges, small diagonal pieces in corners"):
// blocks where two surfaces meet hold points of both, with directions between theirs; a
// run of them along the edge must not stay a patch of its own, while a real face across
// a corner (a corner cabinet's front) stays.
#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <numbers>

#include "../src/planes/bevels.hpp"
#include "plane_scenes.hpp"

using namespace mlmap;

namespace {

struct Piece {
  Eigen::Vector3d normal;
  double offset;
  std::function<bool(const PlaneBlock&)> takes;
};

}  // namespace

TEST_CASE("dropBevels: a strip along the wall's top between wall and ceiling goes, a corner cabinet's front stays") {
  test::PlaneSceneBuilder scene(0.05, 0.002, 1);
  scene.wallX(0.01, 0.01, 3.0, 0.0, 2.5)
      .wallY(0.01, 0.01, 3.0, 0.0, 2.5)
      .floor(0.01, 0.01, 3.0, 3.0, 2.5)                                       // the ceiling
      .rectangle({0.61, 0.01, 0.0}, {-0.6, 0.6, 0.0}, {0.0, 0.0, 1.8}, 0.01);  // x + y = 0.62
  const BlockGrid grid(scene.map());
  const double diagonal = std::sqrt(0.5);
  const std::vector<Piece> pieces{
      {Eigen::Vector3d::UnitX(), -0.01, [](const PlaneBlock& b) { return b.vertical && b.point.x() < 0.06 && b.point.y() > 0.7; }},
      {Eigen::Vector3d::UnitY(), -0.01, [](const PlaneBlock& b) { return b.vertical && b.point.y() < 0.06 && b.point.x() > 0.7; }},
      {Eigen::Vector3d::UnitZ(), -2.5, [](const PlaneBlock& b) { return !b.vertical && b.point.x() > 0.16 && b.point.y() > 0.7; }},
      // The strip: the ceiling's blocks along the wall x = 0.01, on a plane 45° between.
      {Eigen::Vector3d(diagonal, 0.0, diagonal), -(0.01 + 2.5) * diagonal,
       [](const PlaneBlock& b) { return !b.vertical && b.point.x() >= 0.06 && b.point.x() <= 0.16 && b.point.y() > 0.7; }},
      // The cabinet's front across the corner, 0.44 m from it.
      {Eigen::Vector3d(diagonal, diagonal, 0.0), -0.62 * diagonal,
       [](const PlaneBlock& b) {
         return b.vertical && std::abs(b.point.x() + b.point.y() - 0.62) < 0.05 && b.point.x() > 0.08 && b.point.y() > 0.08;
       }}};
  PatchSet set;
  set.labels.assign(grid.size(), 0);
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    Plane plane;
    plane.id = static_cast<std::int32_t>(k + 1);
    plane.normal = pieces[k].normal;
    plane.offset = pieces[k].offset;
    std::vector<std::uint32_t> blocks;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::uint32_t id = 0; id < grid.size(); ++id) {
      if (set.labels[id] != 0 || !pieces[k].takes(grid.blocks()[id])) continue;
      blocks.push_back(id);
      set.labels[id] = plane.id;
      sum += grid.blocks()[id].point.cast<double>();
    }
    REQUIRE(!blocks.empty());
    plane.centroid = sum / static_cast<double>(blocks.size());
    set.planes.push_back(plane);
    set.blocks.push_back(blocks);
    set.outline_frames.push_back(OutlineFrame{});
    set.outline_runs.emplace_back();
  }
  const std::size_t front_blocks = set.blocks[4].size();
  dropBevels(grid, set, 0.05, 25.0 * std::numbers::pi / 180.0);
  REQUIRE(set.planes.size() == 4);  // the strip went
  for (std::size_t k = 0; k < set.planes.size(); ++k) {
    CHECK(set.planes[k].id == static_cast<std::int32_t>(k + 1));
    for (const std::uint32_t id : set.blocks[k]) CHECK(set.labels[id] == set.planes[k].id);
  }
  CHECK(std::abs(set.planes[3].normal.x() - diagonal) < 1e-9);  // the cabinet's front stays
  CHECK(set.blocks[3].size() == front_blocks);
  std::size_t labelled = 0;
  for (const std::int32_t label : set.labels) labelled += label > 0 ? 1 : 0;
  std::size_t kept = 0;
  for (const auto& blocks : set.blocks) kept += blocks.size();
  CHECK(labelled == kept);  // the strip's blocks belong to no patch
}
