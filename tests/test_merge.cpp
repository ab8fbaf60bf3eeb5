// Merging the maps of two overlapping rooms: registration between the maps, both
// layers fused, a shared wall ending up as one plane, refusals, associativity.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>

#include "mlmap/error.hpp"
#include "mlmap/map/merge.hpp"
#include "mlmap/planes/ermsm.hpp"
#include "mlmap/registration/map_registration.hpp"
#include "mlmap/sim/scene.hpp"
#include "mlmap/sim/simulator.hpp"
#include "room_scenes.hpp"

using namespace mlmap;

namespace {

const std::vector<sim::SimulatedScan>& roomScans() {
  static const std::vector<sim::SimulatedScan> scans = sim::simulate(sim::parseScene(mlmap::test::kRoomsJson, "rooms.json"));
  return scans;
}

// A map of some of the rooms' scans, in the frame whose pose in the world is `frame`.
Map mapOf(std::initializer_list<std::size_t> scan_indices, const Pose& frame, bool with_octree) {
  Map map(MapConfig{0.05, 0.0, 12.0, with_octree});
  for (const std::size_t index : scan_indices) {
    Scan scan = roomScans()[index].scan;
    scan.pose = frame.inverse() * roomScans()[index].true_pose;
    map.insertScan(scan);
  }
  map.compact();
  return map;
}

Pose yawPose(double x, double y, double z, double yaw_deg) {
  Pose pose = Pose::Identity();
  pose.linear() = Eigen::AngleAxisd(yaw_deg * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(x, y, z);
  return pose;
}

double yawDeg(const Pose& pose) {
  const Eigen::Vector3d forward = pose.linear() * Eigen::Vector3d::UnitX();
  return std::atan2(forward.y(), forward.x()) * 180.0 / std::numbers::pi;
}

// The wall patches of `detection` on the plane n·x + offset = 0 (either orientation).
std::vector<const Plane*> patchesOn(const PlaneDetection& detection, const Eigen::Vector3d& normal, double offset) {
  std::vector<const Plane*> found;
  for (const Plane& plane : detection.planes) {
    const double alignment = plane.normal.dot(normal);
    if (std::abs(alignment) < 0.99) continue;
    const double signed_offset = alignment > 0 ? plane.offset : -plane.offset;
    if (std::abs(signed_offset - offset) < 0.1) found.push_back(&plane);
  }
  return found;
}

}  // namespace

TEST_CASE("Merge: ICP places the other room, the shared walls become one plane, the overlap is not doubled") {
  // Room B was mapped in its own frame, turned 25° and shifted from A's.
  const Pose b_frame = yawPose(1.3, -0.8, 0.0, 25.0);
  Map merged = mapOf({0, 1}, Pose::Identity(), true);
  const Map other = mapOf({2, 3}, b_frame, true);
  const Map direct = mapOf({0, 1, 2, 3}, Pose::Identity(), false);

  // A rough guess, as from a floor plan: 0.25 m and 4° off.
  const Pose initial = b_frame * yawPose(0.2, -0.15, 0.0, 4.0);
  const registration::MapRegistration found = registration::registerMaps(merged, other, initial);
  INFO("reason: " << found.reason);
  REQUIRE(found.reliable);
  CHECK(found.overlap > 0.3);
  // Blocks sit at cell centres: the maps' surfaces are quantised to the 5 cm grid, so
  // the match is good to about half a cell.
  CHECK((found.other_to_base.translation() - b_frame.translation()).norm() < 0.03);
  CHECK(std::abs(yawDeg(found.other_to_base) - 25.0) < 0.3);

  const std::size_t base_blocks = merged.blocks().blockCount();
  const MergeStats stats = mergeInto(merged, other, found.other_to_base);
  CHECK(stats.base_blocks == base_blocks);
  CHECK(stats.merged_blocks < stats.base_blocks + stats.other_blocks);
  // One map of all the scans is the reference for "not doubled".
  CHECK(static_cast<double>(stats.merged_blocks) < 1.15 * static_cast<double>(direct.blocks().blockCount()));

  const PlaneDetection detection = detectPlanes(merged.blocks());
  // The south wall (y = 0) and the east wall (x = 8) were seen from both rooms.
  for (const auto& [normal, offset] : {std::pair{Eigen::Vector3d(0, 1, 0), 0.0}, std::pair{Eigen::Vector3d(1, 0, 0), -8.0}}) {
    const auto patches = patchesOn(detection, normal, offset);
    INFO("wall normal " << normal.transpose());
    REQUIRE(patches.size() == 1);
    const double signed_offset = patches[0]->normal.dot(normal) > 0 ? patches[0]->offset : -patches[0]->offset;
    CHECK(std::abs(signed_offset - offset) <= 0.01);
  }

  // The OcTree holds both rooms: the east room's far wall (y = 7, seen only by B) is
  // occupied, and the middle of the east room is free.
  const octomap::OcTreeNode* wall = merged.octree().search(6.0, 6.99, 1.5);
  const octomap::OcTreeNode* wall_voxel = wall != nullptr ? wall : merged.octree().search(6.0, 7.02, 1.5);
  REQUIRE(wall_voxel != nullptr);
  CHECK(merged.octree().isNodeOccupied(wall_voxel));
  const octomap::OcTreeNode* middle = merged.octree().search(6.0, 5.5, 2.0);
  REQUIRE(middle != nullptr);
  CHECK_FALSE(merged.octree().isNodeOccupied(middle));
}

TEST_CASE("Merge: ICP places the other room from the identity, frames up to 1 m and 30 degrees apart") {
  // Rooms mapped apart share no frame: no --initial, the start is the identity.
  const Map base = mapOf({0, 1}, Pose::Identity(), false);
  // The -22 deg frame is the hard one: from the identity the yaw retries took 5 wide ICP runs
  // (8 s) before the walls' dominant directions gave the start (bench/merge_register.py holds
  // the many generated cases). The figure: within 2 cm and 0.2 deg.
  for (const Pose& b_frame : {yawPose(0.7, -0.6, 0.0, 28.0), yawPose(-0.5, 0.8, 0.0, -22.0)}) {
    CAPTURE(yawDeg(b_frame));
    const Map other = mapOf({2, 3}, b_frame, false);
    const registration::MapRegistration found = registration::registerMaps(base, other, Pose::Identity());
    INFO("reason: " << found.reason);
    CHECK(found.reliable);
    CHECK(found.verified);
    CHECK((found.other_to_base.translation() - b_frame.translation()).norm() < 0.02);
    CHECK(std::abs(yawDeg(found.other_to_base) - yawDeg(b_frame)) < 0.2);
    CAPTURE(found.attempts);
    CHECK(found.attempts <= 2);
  }
}

TEST_CASE("Merge: maps that do not overlap are not registered") {
  const Map base = mapOf({0, 1}, Pose::Identity(), false);
  const Map far_away = mapOf({2, 3}, yawPose(60.0, 0.0, 0.0, 0.0), false);
  const registration::MapRegistration found = registration::registerMaps(base, far_away, Pose::Identity());
  CHECK_FALSE(found.reliable);
  CHECK(found.overlap < 0.01);
  CHECK_FALSE(found.reason.empty());
}

TEST_CASE("Merge: (A + B) + C and A + (B + C) agree block by block") {
  const Pose same = Pose::Identity();
  Map left = mapOf({0}, same, false);
  mergeInto(left, mapOf({1}, same, false), same);
  mergeInto(left, mapOf({2, 3}, same, false), same);
  Map right_tail = mapOf({1}, same, false);
  mergeInto(right_tail, mapOf({2, 3}, same, false), same);
  Map right = mapOf({0}, same, false);
  mergeInto(right, right_tail, same);

  const MLMap& a = left.blocks();
  const MLMap& b = right.blocks();
  CHECK(a.cellCount() == b.cellCount());
  std::size_t agreeing = 0;
  for (std::size_t n = 0; n < a.cellCount(); ++n) {
    const auto mine = a.blocksAt(n);
    const auto theirs = b.blocks(a.cellAt(n));
    bool same_blocks = mine.size() == theirs.size();
    for (std::size_t k = 0; same_blocks && k < mine.size(); ++k) {
      same_blocks = std::abs(mine[k].height - theirs[k].height) < 0.01F &&
                    std::abs(mine[k].bottom() - theirs[k].bottom()) < 0.01F;
    }
    agreeing += same_blocks ? 1 : 0;
  }
  CHECK(static_cast<double>(agreeing) > 0.97 * static_cast<double>(a.cellCount()));
}

TEST_CASE("Merge: the OcTrees' log-odds add up, and what cannot merge is refused") {
  Map base(MapConfig{0.1, 0.0, -1.0, true});
  Map other(MapConfig{0.1, 0.0, -1.0, true});
  const octomap::point3d voxel(1.05, 2.05, 0.55);
  base.octree().updateNode(voxel, 0.4F);
  other.octree().updateNode(voxel, 0.7F);
  other.octree().updateNode(octomap::point3d(3.05, 2.05, 0.55), -0.4F);
  mergeInto(base, other, Pose::Identity());
  REQUIRE(base.octree().search(voxel) != nullptr);
  CHECK(base.octree().search(voxel)->getLogOdds() == doctest::Approx(1.1F));
  REQUIRE(base.octree().search(3.05, 2.05, 0.55) != nullptr);
  CHECK(base.octree().search(3.05, 2.05, 0.55)->getLogOdds() == doctest::Approx(-0.4F));

  Pose tilted = Pose::Identity();
  tilted.linear() = Eigen::AngleAxisd(5.0 * std::numbers::pi / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
  CHECK_THROWS_WITH_AS(mergeInto(base, other, tilted), doctest::Contains("gravity-aligned"), Error);
  Map coarse(MapConfig{0.2, 0.0, -1.0, true});
  CHECK_THROWS_WITH_AS(mergeInto(base, coarse, Pose::Identity()), doctest::Contains("cell sizes"), Error);
  Map blocks_only(MapConfig{0.1, 0.0, -1.0, false});
  CHECK_THROWS_WITH_AS(mergeInto(base, blocks_only, Pose::Identity()), doctest::Contains("OcTree"), Error);
}
