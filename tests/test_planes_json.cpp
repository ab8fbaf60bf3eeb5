// The planes JSON export against web/planes.schema.json, and its content.
#include <doctest/doctest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <set>

#include "mlmap/error.hpp"

#include "helpers.hpp"
#include "json_schema.hpp"
#include "mlmap/io/planes_json.hpp"
#include "plane_scenes.hpp"

using namespace mlmap;

namespace {

// A floor and a wall standing on it, at `height`, on a 5 cm map, and its planes.
PlaneDetection floorAndWall(Map& map, double height) {
  test::PlaneSceneBuilder scene(0.05);
  scene.floor(0.0, 0.0, 4.0, 3.0, height).wallX(0.0, 0.0, 3.0, height, 2.6);
  map.blocks() = scene.map();
  return detectPlanes(map.blocks());
}

test::JsonSchema planesSchema() {
  std::ifstream in(test::sourceDir() / "web" / "planes.schema.json");
  return test::JsonSchema(nlohmann::json::parse(in));
}

}  // namespace

TEST_CASE("PlanesJson: an export of a room validates against the schema and says what was found") {
  test::PlaneSceneBuilder scene(0.05);
  scene.floor(0.0, 0.0, 4.0, 3.0, 0.0).floor(0.0, 0.0, 4.0, 3.0, 2.6).wallX(0.0, 0.0, 3.0, 0.0, 2.6);
  scene.floor(1.0, 1.0, 2.2, 1.8, 0.75);
  Map map(MapConfig{0.05, 0.0, -1.0, false});
  map.blocks() = scene.map();
  const PlaneDetection detection = detectPlanes(map.blocks());
  const nlohmann::json json = nlohmann::json::parse(io::planesJson(map, detection, "room.mlmap"));
  const auto error = planesSchema().check(json);
  CHECK_MESSAGE(!error.has_value(), error.value_or(""));
  CHECK(json["schema"] == "mlmap.planes/1");
  REQUIRE(json["planes"].size() == detection.planes.size());
  std::set<std::string> labels;
  for (const auto& plane : json["planes"]) labels.insert(plane["label"].get<std::string>());
  CHECK(labels == std::set<std::string>{"floor", "ceiling", "wall", "table"});
  CHECK(json["map"]["cell_size"] == 0.05);
  CHECK(json["parameters"]["seed"] == 1);
}

TEST_CASE("PlanesJson: the schema checker catches what a broken export would have") {
  const test::JsonSchema schema = planesSchema();
  nlohmann::json json = {{"schema", "mlmap.planes/2"}};
  CHECK(schema.check(json).has_value());
  test::PlaneSceneBuilder scene(0.05);
  scene.floor(0.0, 0.0, 3.0, 3.0, 0.0);
  Map map(MapConfig{0.05, 0.0, -1.0, false});
  map.blocks() = scene.map();
  json = nlohmann::json::parse(io::planesJson(map, detectPlanes(map.blocks()), "floor.mlmap"));
  REQUIRE_FALSE(schema.check(json).has_value());
  json["planes"][0]["label"] = "roof";
  CHECK(schema.check(json).value_or("").find("roof") != std::string::npos);
  json["planes"][0]["label"] = "floor";
  json["planes"][0]["normal"] = {0.0, 1.0};
  CHECK(schema.check(json).value_or("").find("normal") != std::string::npos);
}

TEST_CASE("PlanesJson: a failed write leaves no file") {
  test::TempDir dir;
  Map map(MapConfig{0.1, 0.0, -1.0, false});
  CHECK_THROWS_AS(io::writePlanesJson(dir / "missing" / "p.json", map, detectPlanes(map.blocks()), "m"), Error);
  CHECK(std::filesystem::is_empty(dir.path()));
}

TEST_CASE("PlanesJson: an export reads back to the same planes") {
  Map map(MapConfig{0.05, 0.0, -1.0, false});
  const PlaneDetection detection = floorAndWall(map, 0.0);
  REQUIRE(detection.planes.size() >= 2);
  const PlaneDetection back = io::parsePlanesJson(io::planesJson(map, detection, "room.mlmap"), "room.json");
  REQUIRE(back.planes.size() == detection.planes.size());
  for (std::size_t k = 0; k < back.planes.size(); ++k) {
    const Plane& expected = detection.planes[k];
    const Plane& read = back.planes[k];
    CHECK(read.id == expected.id);
    CHECK(read.label == expected.label);
    CHECK((read.normal - expected.normal).norm() < 1e-12);
    CHECK(read.offset == doctest::Approx(expected.offset));
    CHECK(read.area == doctest::Approx(expected.area));
    CHECK(read.block_count == expected.block_count);
    CHECK(read.outline.size() == expected.outline.size());
    CHECK(read.source == expected.source);
  }
  CHECK(back.stats.candidates == detection.stats.candidates);
  CHECK(back.config.kappa_deg == detection.config.kappa_deg);
  CHECK(back.config.seed == detection.config.seed);
  // σ the build assumed, where the planes measured theirs: `mlmap label` caps a patch's
  // tolerance by the larger of the two.
  PlaneDetection measured = detection;
  measured.stats.prior_noise = 0.03;
  measured.stats.passes = 2;
  const PlaneDetection measured_back = io::parsePlanesJson(io::planesJson(map, measured, "room.mlmap"), "room.json");
  CHECK(measured_back.stats.prior_noise == doctest::Approx(0.03));
  CHECK(measured_back.stats.passes == 2);
  CHECK(back.stats.prior_noise == doctest::Approx(detection.stats.prior_noise));
  CHECK(back.stats.passes == detection.stats.passes);
  // The sparse gap the planes were grown with (0.6 m by default) is recorded and read back.
  PlaneDetection no_growth = detection;
  no_growth.config.sparse_gap = 0.0;
  CHECK(io::parsePlanesJson(io::planesJson(map, no_growth, "room.mlmap"), "room.json").config.sparse_gap == 0.0);
  CHECK(back.config.sparse_gap == doctest::Approx(detection.config.sparse_gap));
}

TEST_CASE("PlanesJson: a plane per line, outline corners and centroids to the micrometre") {
  Map map(MapConfig{0.05, 0.0, -1.0, false});
  // A height that is not whole cells, so the corners lifted onto the planes are not
  // round numbers before the export rounds them.
  const PlaneDetection detection = floorAndWall(map, 0.0123456789);
  REQUIRE(detection.planes.size() >= 2);
  const std::string text = io::planesJson(map, detection, "room.mlmap");
  std::istringstream lines(text);
  std::string line;
  std::size_t plane_lines = 0;
  const auto onMicrometres = [](double metres) {
    return std::abs(metres * 1e6 - std::round(metres * 1e6)) < 1e-3;
  };
  while (std::getline(lines, line)) {
    if (line.rfind("    {", 0) != 0) continue;
    if (line.back() == ',') line.pop_back();
    const nlohmann::json plane = nlohmann::json::parse(line);
    const Plane& expected = detection.planes[plane_lines++];
    CHECK(plane["id"] == expected.id);
    REQUIRE(plane["outline"].size() == expected.outline.size());
    for (std::size_t k = 0; k < expected.outline.size(); ++k) {
      for (int axis = 0; axis < 3; ++axis) {
        const double written = plane["outline"][k][axis].get<double>();
        CHECK(onMicrometres(written));
        CHECK(std::abs(written - expected.outline[k][axis]) <= 0.5e-6 + 1e-12);
      }
    }
    for (int axis = 0; axis < 3; ++axis) CHECK(onMicrometres(plane["centroid"][axis].get<double>()));
    // Normals keep every digit: a plane's offset is only as good as its normal.
    for (int axis = 0; axis < 3; ++axis) CHECK(plane["normal"][axis].get<double>() == expected.normal[axis]);
  }
  CHECK(plane_lines == detection.planes.size());
  // The measured noise is a float: written as one (at most 9 significant digits), it
  // reads back to the same float.
  const nlohmann::json parameters = nlohmann::json::parse(text)["parameters"];
  const std::string noise_text = parameters["noise"].dump();
  CAPTURE(noise_text);
  CHECK(noise_text.find_first_not_of("0.") != std::string::npos);
  CHECK(noise_text.size() - noise_text.find_first_not_of("0.") <= 10);
  CHECK(static_cast<float>(parameters["noise"].get<double>()) == static_cast<float>(detection.config.noise));
}

TEST_CASE("PlanesJson: the reader refuses what is not an export, naming the element") {
  test::PlaneSceneBuilder scene(0.05);
  scene.floor(0.0, 0.0, 3.0, 3.0, 0.0);
  Map map(MapConfig{0.05, 0.0, -1.0, false});
  map.blocks() = scene.map();
  const nlohmann::json good = nlohmann::json::parse(io::planesJson(map, detectPlanes(map.blocks()), "f.mlmap"));
  REQUIRE_FALSE(good["planes"].empty());
  const auto refused = [](const nlohmann::json& json, const char* fragment) {
    CHECK_THROWS_WITH_AS(io::parsePlanesJson(json.dump(), "x.json"), doctest::Contains(fragment), Error);
  };
  CHECK_THROWS_WITH_AS(io::parsePlanesJson("{\"schema\": ", "x.json"), doctest::Contains("x.json: not valid JSON"),
                       Error);
  CHECK_THROWS_WITH_AS(io::parsePlanesJson("[1, 2]", "x.json"), doctest::Contains("expected an object"), Error);
  nlohmann::json json = good;
  json["schema"] = "mlmap.planes/2";
  refused(json, "schema");
  json = good;
  json["planes"][0]["normal"] = {0.0, 1.0};
  refused(json, "planes[0].normal: expected 3 numbers");
  json = good;
  json["planes"][0]["normal"] = {0.0, 2.0, 0.0};
  refused(json, "not a unit vector");
  json = good;
  json["planes"][0]["id"] = -4;
  refused(json, "planes[0].id: out of range");
  json = good;
  json["planes"][0]["label"] = "roof";
  refused(json, "planes[0].label");
  json = good;
  json["planes"][0]["outline"][0] = {1.0, "a", 2.0};
  refused(json, "planes[0].outline[0][1]: expected a number");
  json = good;
  json["planes"].push_back(json["planes"][0]);
  refused(json, "appears twice");
  json = good;
  json["parameters"].erase("seed");
  refused(json, "parameters: missing \"seed\"");
  json = good;
  json["timings"]["detection_s"] = "fast";
  refused(json, "timings.detection_s");
}

TEST_CASE("PlanesJson: integer parameters out of their type's range are refused, not converted") {
  test::PlaneSceneBuilder scene(0.05);
  scene.floor(0.0, 0.0, 3.0, 3.0, 0.0);
  Map map(MapConfig{0.05, 0.0, -1.0, false});
  map.blocks() = scene.map();
  nlohmann::json json = nlohmann::json::parse(io::planesJson(map, detectPlanes(map.blocks()), "f.mlmap"));
  CHECK(json["parameters"].contains("noise"));
  CHECK(json["parameters"].contains("stack_gap"));
  json["parameters"]["batch_size"] = 1e300;
  CHECK_THROWS_WITH_AS(io::parsePlanesJson(json.dump(), "x.json"), doctest::Contains("parameters.batch_size: out of range"),
                       Error);
}
