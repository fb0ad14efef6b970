// SPDX-License-Identifier: Apache-2.0
// The SPIDAR description files (common/spidar/geometry.h, grip_geometry.h): the shipped files are the built-in
// devices, bad files are errors naming the file and key, and the hash tells devices apart.

#include "common/spidar/geometry.h"
#include "common/spidar/grip_geometry.h"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>

using namespace impetus;

namespace {

std::string write_file(const std::string& name, const std::string& text) {
  const std::string path = std::string(IMPETUS_BINARY_DIR) + "/" + name + "-" + std::to_string(getpid()) + ".json";
  std::ofstream(path) << text;
  return path;
}

std::string error_of(const std::string& path) {
  try {
    load_spidar_geometry(path);
  } catch (const SpidarGeometryError& error) {
    return error.what();
  }
  return "";
}

}  // namespace

TEST_CASE("the shipped desktop SPIDAR file describes the built-in geometry") {
  const SpidarDevice device =
      parse_device_spec("spidar:" + std::string(IMPETUS_SOURCE_DIR) + "/common/spidar/desktop_spidar.json");
  CHECK(geometry_hash(device.geometry) == geometry_hash(SpidarGeometry{}));
  CHECK(parse_device_spec("spidar").source == "built-in");
}

TEST_CASE("a device file with an unknown key or an unusable value is an error naming the file and the key") {
  const std::string typo = write_file("typo", R"({"frame_side": 0.4})");
  CHECK_THAT(error_of(typo), Catch::Contains(typo) && Catch::Contains("frame_side"));
  const std::string negative = write_file("negative", R"({"tension_min_N": -1})");
  CHECK_THAT(error_of(negative), Catch::Contains("tension_min_N") && Catch::Contains("-1"));
  const std::string inverted = write_file("inverted", R"({"tension_min_N": 5, "tension_max_N": 2})");
  CHECK_THAT(error_of(inverted), Catch::Contains("tension_max_N"));
  const std::string centre = write_file("centre", R"({"centre_m": [0, 0]})");
  CHECK_THAT(error_of(centre), Catch::Contains("centre_m"));
  CHECK_THAT(error_of("/nonexistent/spidar.json"), Catch::Contains("/nonexistent/spidar.json"));
  CHECK_THROWS_AS(parse_device_spec("phantom"), SpidarGeometryError);
  for (const std::string& path : {typo, negative, inverted, centre}) std::remove(path.c_str());
}

TEST_CASE("a device file with extreme, deep or huge content gives a short error naming the file") {
  // Values beyond the physical bounds, a centre nested a million levels deep (quoting it used to recurse once per
  // level), a 10 MB key and a number too large for a double (nlohmann's out_of_range, not a parse error).
  std::string deep = R"({"centre_m": [0, 0, )";
  deep.append(1'000'000, '[').append(1'000'000, ']').append("]}");
  std::string huge_key = "{\"";
  huge_key.append(10'000'000, 'k').append("\": 1}");
  struct Case {
    std::string name, text, expected;
  };
  const Case cases[] = {
      {"huge_frame", R"({"frame_side_m": 1e300})", "at most 10"},
      {"huge_force", R"({"max_force_N": 1e9})", "at most 1000"},
      {"far_centre", R"({"centre_m": [1e12, 0, 0]})", "within"},
      {"deep", deep, "centre_m"},
      {"huge_key", huge_key, "unknown key"},
      {"overflow", R"({"frame_side_m": 1e999})", "not valid JSON"},
  };
  for (const Case& test_case : cases) {
    INFO(test_case.name);
    const std::string path = write_file(test_case.name, test_case.text);
    try {
      load_spidar_geometry(path);
      FAIL("expected SpidarGeometryError");
    } catch (const SpidarGeometryError& error) {
      const std::string message = error.what();
      INFO(message.substr(0, 300));
      CHECK(message.size() < 600);
      CHECK_THAT(message, Catch::Contains(path) && Catch::Contains(test_case.expected));
    }
  }
}

TEST_CASE("devices that differ in any value hash differently") {
  const SpidarGeometry base;
  SpidarGeometry wider = base;
  wider.frame_side_m = 0.6;
  SpidarGeometry moved = base;
  moved.centre_m[2] += 1e-3;
  SpidarGeometry stronger = base;
  stronger.max_force_N = 12.0;
  CHECK(geometry_hash(base) == geometry_hash(SpidarGeometry{}));
  CHECK(geometry_hash(wider) != geometry_hash(base));
  CHECK(geometry_hash(moved) != geometry_hash(base));
  CHECK(geometry_hash(stronger) != geometry_hash(base));
}

TEST_CASE("a grip device file: the shipped one is the built-in grip, bad ones name the file and key") {
  const GripDevice shipped =
      parse_grip_spec("grip:" + std::string(IMPETUS_SOURCE_DIR) + "/common/spidar/desktop_grip.json");
  CHECK(grip_geometry_hash(shipped.geometry) == grip_geometry_hash(SpidarGripGeometry{}));
  CHECK(parse_grip_spec("grip").source == "built-in");
  const std::string wider = write_file("grip_wider", R"({"frame_side_m": 0.6, "grip_radius_m": 0.03})");
  const GripDevice read = parse_grip_spec("grip:" + wider);
  CHECK(read.geometry.frame_side_m == 0.6);
  CHECK(read.geometry.grip_radius_m == 0.03);
  CHECK(read.geometry.tension_min_N == SpidarGripGeometry{}.tension_min_N);  // a missing key keeps its default
  CHECK(read.source == wider);
  CHECK(grip_geometry_hash(read.geometry) != grip_geometry_hash(SpidarGripGeometry{}));

  const auto error_of_grip = [](const std::string& path) -> std::string {
    try {
      load_grip_geometry(path);
    } catch (const SpidarGeometryError& error) {
      return error.what();
    }
    return "";
  };
  struct Case {
    std::string name, text, key, expected;
  };
  const Case cases[] = {
      {"grip_typo", R"({"grip_radius": 0.02})", "grip_radius", "unknown key"},
      {"grip_wide", R"({"grip_radius_m": 0.2})", "grip_radius_m", "at most 0.1"},  // a quarter of the 0.4 m frame
      {"grip_inverted", R"({"tension_min_N": 5, "tension_max_N": 2})", "tension_max_N", "must exceed"},
      {"grip_centre", R"({"centre_m": [0, "x", 0]})", "centre_m", "three numbers"},
      {"grip_count", R"({"metres_per_count": -1})", "metres_per_count", "-1"},
  };
  for (const Case& test_case : cases) {
    INFO(test_case.name);
    const std::string path = write_file(test_case.name, test_case.text);
    CHECK_THAT(error_of_grip(path), Catch::Contains(path) && Catch::Contains(test_case.key) &&
                                        Catch::Contains(test_case.expected));
    std::remove(path.c_str());
  }
  CHECK_THAT(error_of_grip("/nonexistent/grip.json"), Catch::Contains("/nonexistent/grip.json"));
  CHECK_THROWS_WITH(parse_grip_spec("spidar"), Catch::Contains("'grip' or 'grip:FILE.json'"));
  std::remove(wider.c_str());
}
