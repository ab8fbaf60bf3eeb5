// detectPlanes' second pass (σ measured on the first pass's planes) reuses the first
// pass's eRMSM blocks and direction vectors where its σ and ε leave them unchanged, and
// finds exactly the planes a single detection with that σ and ε finds.
#include <doctest/doctest.h>

#include <cmath>

#include "mlmap/planes/block_grid.hpp"
#include "mlmap/planes/direction_vectors.hpp"
#include "mlmap/planes/ermsm.hpp"
#include "plane_scenes.hpp"

using namespace mlmap;

namespace {

// A 4 × 3 m room at 5 cm cells: floor, two walls, a table; points scatter by `noise`,
// the build assumed `assumed` for them.
test::PlaneSceneBuilder room(double noise, double assumed, unsigned seed) {
  test::PlaneSceneBuilder scene(0.05, noise, seed);
  scene.withNoise(noise, assumed * assumed)
      .rectangle({0.0, 0.0, 0.0}, {4.0, 0.0, 0.0}, {0.0, 3.0, 0.0}, 0.01)
      .wallX(0.0, 0.0, 3.0, 0.0, 2.4)
      .wallY(0.0, 0.0, 4.0, 0.0, 2.4)
      .rectangle({1.0, 1.0, 0.75}, {1.2, 0.0, 0.0}, {0.0, 0.8, 0.0}, 0.01);
  return scene;
}

// The same patches, bit for bit (the map's labels follow from them).
void checkSamePlanes(const PlaneDetection& a, const PlaneDetection& b) {
  REQUIRE(a.planes.size() == b.planes.size());
  for (std::size_t k = 0; k < a.planes.size(); ++k) {
    CAPTURE(k);
    CHECK(a.planes[k].normal == b.planes[k].normal);
    CHECK(a.planes[k].offset == b.planes[k].offset);
    CHECK(a.planes[k].block_count == b.planes[k].block_count);
    CHECK(a.planes[k].area == b.planes[k].area);
    CHECK(a.planes[k].outline == b.planes[k].outline);
  }
  CHECK(a.stats.labelled_blocks == b.stats.labelled_blocks);
}

// One detection told the σ and ε a measured detection ended with: it must find the same.
void checkSameAsOnePass(MLMap& map, const PlaneDetection& measured) {
  ErmsmConfig given;
  given.noise = measured.config.noise;
  given.epsilon = measured.config.epsilon;
  given.ladder_blocks = measured.config.ladder_blocks;
  const PlaneDetection once = detectPlanes(map, given);
  CHECK(once.stats.passes == 1);
  checkSamePlanes(measured, once);
}

}  // namespace

TEST_CASE("Planes, second pass: σ kept, the first pass's blocks and directions are reused") {
  // Points scatter as the build assumed: the measured σ stays within 25 % of it.
  test::PlaneSceneBuilder scene = room(0.01, 0.01, 1);
  const PlaneDetection measured = detectPlanes(scene.map());
  CAPTURE(measured.config.noise);
  REQUIRE(measured.stats.passes == 2);
  REQUIRE(measured.stats.prior_noise == 0.0);
  CHECK(measured.stats.grids_built == 1);
  CHECK(measured.stats.direction_fields == 1);
  CHECK(measured.planes.size() >= 4);
  checkSameAsOnePass(scene.map(), measured);
}

TEST_CASE("Planes, second pass: σ moved, what depends on it is made again") {
  // Points scatter by 1.5 cm where the build assumed 3 mm (PCL's office1): σ moves, the
  // level band (5 σ) with it, and ε (3 σ) beyond the cell's 5 cm.
  test::PlaneSceneBuilder scene = room(0.02, 0.003, 2);
  const PlaneDetection measured = detectPlanes(scene.map());
  CAPTURE(measured.config.noise);
  REQUIRE(measured.stats.passes == 2);
  REQUIRE(measured.stats.prior_noise > 0.0);
  CHECK(measured.config.epsilon > 0.05);
  CHECK(measured.stats.direction_fields == 2);
  checkSameAsOnePass(scene.map(), measured);
}

TEST_CASE("Planes, second pass: where the short first search labels too few blocks, the whole one measures σ") {
  // 2.5 cm of scatter where 3 mm were assumed: the first 100 idle candidates find too
  // little to measure σ on, the whole search of 300 does. Ladders of six: with four, the
  // walls' columns, split by the scatter into short blocks, are wall blocks again and the
  // short search finds enough.
  test::PlaneSceneBuilder scene = room(0.025, 0.003, 2);
  ErmsmConfig config;
  config.ladder_blocks = 6;
  const PlaneDetection measured = detectPlanes(scene.map(), config);
  CAPTURE(measured.config.noise);
  REQUIRE(measured.stats.passes == 3);
  CHECK(measured.stats.prior_noise > 0.0);
  CHECK(measured.config.noise > 0.015);
  CHECK(measured.stats.grids_built <= 2);
  checkSameAsOnePass(scene.map(), measured);
}

TEST_CASE("Planes, second pass: directions updated where another level band changed some blocks are the whole field's") {
  // A noisy 1 m² board in a quiet room: its cells' blocks, 5-10 cm deep, are level under
  // a 10 cm band and vertical under a 5 cm one; the rest of the map is the same in both.
  test::PlaneSceneBuilder scene = room(0.005, 0.005, 3);
  scene.withNoise(0.03, 0.0004).rectangle({2.5, 0.5, 0.4}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 0.02);
  const BlockGrid narrow(scene.map(), BlockGridConfig{.stack_gap = 0.06, .level_band = 0.05});
  const BlockGrid wide(scene.map(), BlockGridConfig{.stack_gap = 0.06, .level_band = 0.10});
  REQUIRE(narrow.size() == wide.size());
  std::vector<std::uint32_t> changed;
  for (std::uint32_t id = 0; id < narrow.size(); ++id) {
    if (narrow.blocks()[id].vertical != wide.blocks()[id].vertical || narrow.blocks()[id].point != wide.blocks()[id].point) {
      changed.push_back(id);
    }
  }
  CAPTURE(changed.size());
  CHECK(!changed.empty());
  CHECK(changed.size() < narrow.size() / 20);  // so only the board's surroundings are computed again
  DirectionConfig config;
  config.radius = 2;
  config.max_radius = 4;
  config.max_tilt = 0.05;
  config.height_tolerance = 0.06F;
  const DirectionField whole = directionField(wide, config);
  const DirectionField updated = updatedDirectionField(wide, config, directionField(narrow, config), changed);
  REQUIRE(updated.vectors.size() == whole.vectors.size());
  std::size_t differing = 0;
  for (std::size_t id = 0; id < whole.vectors.size(); ++id) {
    const bool same_tilt = updated.tilts[id] == whole.tilts[id] || (std::isnan(updated.tilts[id]) && std::isnan(whole.tilts[id]));
    if (updated.vectors[id] != whole.vectors[id] || !same_tilt) ++differing;
  }
  CHECK(differing == 0);
}
