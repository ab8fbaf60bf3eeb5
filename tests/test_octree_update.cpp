// The OcTree layer's ray insertion equals OctoMap's own insertPointCloud, voxel for
// voxel, with either semantics (discretize true and false) and with a range limit.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "../src/map/octree_update.hpp"
#include "../src/map/octree_walk.hpp"
#include "mlmap/map/map.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

using namespace mlmap;

namespace {

// A 4 x 3 x 2.5 m box room scanned from `origin`: a fan of rays, each ending on the
// first wall it meets, plus a table top that shadows part of the floor.
Scan roomScan(const Eigen::Vector3d& origin, double yaw) {
  Scan scan;
  scan.pose = Eigen::Translation3d(origin) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
  const Eigen::Vector3d low(-2.0, -1.5, 0.0);
  const Eigen::Vector3d high(2.0, 1.5, 2.5);
  const Eigen::Matrix3d rotation = scan.pose.rotation();
  for (double elevation = -1.3; elevation <= 1.3; elevation += 0.045) {
    for (double azimuth = -3.1; azimuth <= 3.1; azimuth += 0.037) {
      const Eigen::Vector3d local(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                                  std::sin(elevation));
      const Eigen::Vector3d direction = rotation * local;
      double range = 1e9;
      for (int axis = 0; axis < 3; ++axis) {
        if (direction[axis] > 1e-9) range = std::min(range, (high[axis] - origin[axis]) / direction[axis]);
        if (direction[axis] < -1e-9) range = std::min(range, (low[axis] - origin[axis]) / direction[axis]);
      }
      if (direction.z() < -1e-9) {  // the table top at z = 0.7 over x, y in [0.5, 1.5] x [-0.5, 0.5]
        const double to_table = (0.7 - origin.z()) / direction.z();
        const Eigen::Vector3d at = origin + to_table * direction;
        if (to_table > 0 && at.x() > 0.5 && at.x() < 1.5 && std::abs(at.y()) < 0.5) range = std::min(range, to_table);
      }
      scan.points.push_back(local * range);
    }
  }
  return scan;
}

std::vector<Scan> roomScans() {
  std::vector<Scan> scans;
  const std::vector<Eigen::Vector3d> origins{{0.013, 0.021, 1.204}, {-1.1, 0.6, 0.9}, {1.3, -0.8, 1.5}, {0.4, 0.9, 0.35}};
  for (int round = 0; round < 2; ++round) {  // twice: voxels saturate and whole nodes prune
    for (std::size_t k = 0; k < origins.size(); ++k) scans.push_back(roomScan(origins[k], 0.3 * static_cast<double>(k)));
  }
  return scans;
}

// The scans into `tree` by OctoMap's own insertPointCloud.
void insertByOctomap(octomap::OcTree& tree, const std::vector<Scan>& scans, double max_range, bool discretize) {
  for (const Scan& scan : scans) {
    octomap::Pointcloud cloud;
    for (std::size_t p = 0; p < scan.size(); ++p) {
      const Eigen::Vector3d world = scan.worldPoint(p);
      cloud.push_back(static_cast<float>(world.x()), static_cast<float>(world.y()), static_cast<float>(world.z()));
    }
    const Eigen::Vector3d origin = scan.pose.translation();
    tree.insertPointCloud(cloud,
                          octomap::point3d(static_cast<float>(origin.x()), static_cast<float>(origin.y()),
                                           static_cast<float>(origin.z())),
                          max_range, false, discretize);
  }
}

octomap::OcTree octomapReference(const std::vector<Scan>& scans, double resolution, double max_range, bool discretize) {
  octomap::OcTree tree(resolution);
  insertByOctomap(tree, scans, max_range, discretize);
  return tree;
}

// Every finest voxel one tree knows (pruned leaves stand for all voxels inside them)
// has the same log-odds in the other. Returns the number of voxels compared.
std::size_t checkVoxelsIn(const octomap::OcTree& from, const octomap::OcTree& in) {
  std::size_t voxels = 0;
  std::size_t mismatches = 0;
  for (auto it = from.begin_leafs(); it != from.end_leafs(); ++it) {
    const unsigned side = 1U << (from.getTreeDepth() - it.getDepth());
    const octomap::OcTreeKey corner = from.adjustKeyAtDepth(it.getKey(), it.getDepth());
    const octomap::OcTreeKey base(static_cast<octomap::key_type>(corner[0] - side / 2 * (side > 1)),
                                  static_cast<octomap::key_type>(corner[1] - side / 2 * (side > 1)),
                                  static_cast<octomap::key_type>(corner[2] - side / 2 * (side > 1)));
    for (unsigned x = 0; x < side; ++x) {
      for (unsigned y = 0; y < side; ++y) {
        for (unsigned z = 0; z < side; ++z) {
          const octomap::OcTreeKey key(static_cast<octomap::key_type>(base[0] + x),
                                       static_cast<octomap::key_type>(base[1] + y),
                                       static_cast<octomap::key_type>(base[2] + z));
          const octomap::OcTreeNode* other = in.search(key);
          ++voxels;
          if (other == nullptr || std::abs(other->getLogOdds() - it->getLogOdds()) > 1e-5F) ++mismatches;
        }
      }
    }
  }
  CHECK(mismatches == 0);
  return voxels;
}

// Every inner node holds the largest log-odds of its children, as updateInnerOccupancy leaves it.
std::size_t innerNodesOutOfDate(const octomap::OcTree& tree) {
  std::size_t wrong = 0;
  for (auto it = tree.begin_tree(); it != tree.end_tree(); ++it) {
    if (!tree.nodeHasChildren(&*it)) continue;
    if (it->getLogOdds() != it->getMaxChildLogOdds()) ++wrong;
  }
  return wrong;
}

void checkSameAsOctomap(double resolution, double max_range, bool exact_rays) {
  const std::vector<Scan> scans = roomScans();
  MapConfig config;
  config.cell_size = resolution;
  config.max_range = max_range;
  config.exact_rays = exact_rays;
  Map map(config);
  for (const Scan& scan : scans) map.insertIntoOctree(scan);
  const octomap::OcTree reference = octomapReference(scans, resolution, max_range, !exact_rays);
  const std::size_t ours = checkVoxelsIn(map.octree(), reference);
  const std::size_t theirs = checkVoxelsIn(reference, map.octree());
  CHECK(ours == theirs);
  CHECK(ours > 10000);
  CHECK(innerNodesOutOfDate(map.octree()) == 0);
  std::size_t saturated = 0;
  for (auto it = map.octree().begin_leafs(); it != map.octree().end_leafs(); ++it) {
    saturated += it->getLogOdds() <= map.octree().getClampingThresMinLog() ? 1 : 0;
  }
  CHECK(saturated > 0);  // the second round reaches the clamping bound and its early abort
}

}  // namespace

TEST_CASE("OcTree update: one ray per end voxel equals OctoMap's discretized insertPointCloud voxel for voxel") {
  checkSameAsOctomap(0.1, -1.0, false);
  checkSameAsOctomap(0.07, 2.2, false);
}

TEST_CASE("OcTree update: rays along a voxel plane (a direction component exactly 0) as OctoMap casts them") {
  // The scanner at a voxel centre: a ray to the centre of any end voxel in the same
  // row, column or layer has a direction component of exactly 0 (step 0, t = DBL_MAX).
  std::vector<Scan> scans{roomScan({0.05, 0.05, 1.25}, 0.0), roomScan({-0.95, 0.45, 0.75}, 0.2)};
  MapConfig config;
  config.cell_size = 0.1;
  Map map(config);
  for (const Scan& scan : scans) map.insertIntoOctree(scan);
  const octomap::OcTree reference = octomapReference(scans, 0.1, -1.0, true);
  CHECK(checkVoxelsIn(map.octree(), reference) == checkVoxelsIn(reference, map.octree()));
  CHECK(map.octree().size() == reference.size());
}

TEST_CASE("OcTree update: exact rays equal OctoMap's per-point insertPointCloud voxel for voxel") {
  checkSameAsOctomap(0.1, -1.0, true);
  checkSameAsOctomap(0.07, 2.2, true);
}

TEST_CASE("OcTree update: scans added to a pruned tree expand only the nodes they change") {
  const std::vector<Scan> scans = roomScans();
  MapConfig config;
  config.cell_size = 0.1;
  Map map(config);
  for (std::size_t k = 0; k < 4; ++k) map.insertIntoOctree(scans[k]);
  map.octree().prune();
  for (std::size_t k = 4; k < scans.size(); ++k) map.insertIntoOctree(scans[k]);
  const octomap::OcTree reference = octomapReference(scans, 0.1, -1.0, true);
  checkVoxelsIn(map.octree(), reference);
  checkVoxelsIn(reference, map.octree());
  CHECK(innerNodesOutOfDate(map.octree()) == 0);
}

namespace {

// The scans into `tree` with the subtrees split at `split_depth`, on two threads.
void insertSplit(octomap::OcTree& tree, const std::vector<Scan>& scans, unsigned split_depth) {
#ifdef _OPENMP
  const int threads = omp_get_max_threads();
  omp_set_num_threads(2);
#endif
  for (const Scan& scan : scans) detail::insertRays(tree, scan, {-1.0, false, split_depth});
#ifdef _OPENMP
  omp_set_num_threads(threads);
#endif
}

void checkSameTrees(const octomap::OcTree& ours, const octomap::OcTree& reference) {
  CHECK(checkVoxelsIn(ours, reference) == checkVoxelsIn(reference, ours));
  CHECK(innerNodesOutOfDate(ours) == 0);
  CHECK(ours.size() == ours.calcNumNodes());  // the node count kept beside the threads' walks
  CHECK(ours.size() == reference.size());
}

// Every voxel of the 32³ block below and beside the room's centre saturated free, then
// pruned: one leaf at depth 11 that the scans' hits must expand and their misses leave.
void saturateBlock(octomap::OcTree& tree) {
  for (unsigned x = 32736; x < 32768; ++x) {
    for (unsigned y = 32736; y < 32768; ++y) {
      for (unsigned z = 32768; z < 32800; ++z) {
        tree.setNodeValue(octomap::OcTreeKey(static_cast<octomap::key_type>(x), static_cast<octomap::key_type>(y),
                                             static_cast<octomap::key_type>(z)),
                          tree.getClampingThresMinLog(), true);
      }
    }
  }
  tree.updateInnerOccupancy();
  tree.prune();
}

}  // namespace

TEST_CASE("OcTree update: subtrees updated on two threads give OctoMap's tree at any split depth") {
  const std::vector<Scan> scans = roomScans();
  const octomap::OcTree reference = octomapReference(scans, 0.07, -1.0, true);
  for (const unsigned split : {1U, 5U, 9U, 11U, 12U}) {
    CAPTURE(split);
    octomap::OcTree tree(0.07);
    insertSplit(tree, scans, split);
    checkSameTrees(tree, reference);
  }
}

TEST_CASE("OcTree update: a pruned node above the split depth is expanded as OctoMap expands it") {
  const std::vector<Scan> scans = roomScans();
  octomap::OcTree reference(0.1);
  saturateBlock(reference);
  REQUIRE(reference.search(octomap::OcTreeKey(32740, 32740, 32770), 11) != nullptr);
  REQUIRE_FALSE(reference.nodeHasChildren(reference.search(octomap::OcTreeKey(32740, 32740, 32770), 11)));
  insertByOctomap(reference, scans, -1.0, true);
  // Split below the pruned leaf (the serial walk), at it (a subtree's top) and above it.
  for (const unsigned split : {12U, 11U, 6U}) {
    CAPTURE(split);
    octomap::OcTree tree(0.1);
    saturateBlock(tree);
    insertSplit(tree, scans, split);
    checkSameTrees(tree, reference);
  }
}

namespace {

using octomap::OcTreeKey;

OcTreeKey keyAt(unsigned x, unsigned y, unsigned z) {
  return OcTreeKey(static_cast<octomap::key_type>(x), static_cast<octomap::key_type>(y),
                   static_cast<octomap::key_type>(z));
}

// Calls visit(key) for every key of the box [low, low + size) (size voxels a side).
template <typename Visit>
void forBox(unsigned x0, unsigned y0, unsigned z0, unsigned size, Visit&& visit) {
  for (unsigned x = x0; x < x0 + size; ++x) {
    for (unsigned y = y0; y < y0 + size; ++y) {
      for (unsigned z = z0; z < z0 + size; ++z) visit(keyAt(x, y, z));
    }
  }
}

// A tree with pruned leaves at depths 11 and 12: saturated free, once missed, saturated occupied.
void prunedBlocks(octomap::OcTree& tree) {
  forBox(32768, 32768, 32768, 32, [&](const OcTreeKey& key) { tree.setNodeValue(key, tree.getClampingThresMinLog(), true); });
  forBox(32800, 32768, 32768, 16, [&](const OcTreeKey& key) { tree.setNodeValue(key, tree.getProbMissLog(), true); });
  forBox(32768, 32800, 32768, 16, [&](const OcTreeKey& key) { tree.setNodeValue(key, tree.getClampingThresMaxLog(), true); });
  tree.updateInnerOccupancy();
  tree.prune();
}

}  // namespace

TEST_CASE("OcTree update: nodes whose voxels all take the same update end as OctoMap's voxel-by-voxel update") {
  // The scan's voxels: whole pruned nodes alike (saturated and not, free and hit),
  // new nodes alike (a 16³ chunk, 8 chunks of a depth-11 node, 8-voxel groups), and
  // nodes almost alike (one voxel hit, one chunk of eight missing).
  std::vector<OcTreeKey> free;
  std::vector<OcTreeKey> hit;
  const auto add = [](std::vector<OcTreeKey>& keys) { return [&keys](const OcTreeKey& key) { keys.push_back(key); }; };
  forBox(32768, 32768, 32768, 32, add(free));   // the saturated free block: left as it is
  forBox(32800, 32768, 32768, 16, add(free));   // the once-missed block: missed again
  forBox(32768, 32800, 32768, 16, add(hit));    // the saturated occupied block: hit
  forBox(32768, 32768, 32800, 32, add(free));   // new: a whole depth-11 node
  forBox(32832, 32768, 32768, 16, add(hit));    // new: a whole chunk hit
  forBox(32832, 32800, 32768, 16, add(free));   // new: a chunk all free but one voxel hit
  hit.push_back(keyAt(32835, 32805, 32770));
  forBox(32768, 32832, 32768, 32, [&](const OcTreeKey& key) {  // new: 7 of the 8 chunks of a depth-11 node
    if (!(key[0] >= 32784 && key[1] >= 32848 && key[2] >= 32784)) free.push_back(key);
  });
  forBox(32864, 32864, 32864, 2, add(free));    // new: one depth-15 node
  forBox(32866, 32864, 32864, 4, add(hit));     // new: a depth-14 node
  free.push_back(keyAt(32870, 32864, 32864));   // and a lone voxel

  octomap::OcTree reference(0.05);
  prunedBlocks(reference);
  // insertPointCloud's order: free (those not hit), then hit
  const octomap::KeySet hit_set(hit.begin(), hit.end());
  for (const OcTreeKey& key : free) {
    if (hit_set.count(key) == 0) reference.updateNode(key, false);
  }
  for (const OcTreeKey& key : hit) reference.updateNode(key, true);

  detail::KeyBits free_bits;
  detail::KeyBits hit_bits;
  for (const OcTreeKey& key : free) free_bits.insert(key);
  for (const OcTreeKey& key : hit) hit_bits.insert(key);
  std::vector<std::uint64_t> codes = free_bits.chunkCodes();
  codes.insert(codes.end(), hit_bits.chunkCodes().begin(), hit_bits.chunkCodes().end());
  std::sort(codes.begin(), codes.end());
  codes.erase(std::unique(codes.begin(), codes.end()), codes.end());
  std::vector<detail::ChunkUpdate> chunks;
  for (const std::uint64_t code : codes) chunks.push_back({code, free_bits.find(code), hit_bits.find(code)});

  for (const unsigned split : {0U, 12U, 9U}) {  // chosen, the chunks' depth, above the pruned leaves
    CAPTURE(split);
    octomap::OcTree tree(0.05);
    prunedBlocks(tree);
    detail::updateTree(tree, chunks, split);
    checkSameTrees(tree, reference);
    CHECK(tree.search(keyAt(32770, 32770, 32770))->getLogOdds() == tree.getClampingThresMinLog());
    CHECK(tree.search(keyAt(32770, 32770, 32800)) == tree.search(keyAt(32770, 32770, 32800), 11));  // one leaf
  }
}
