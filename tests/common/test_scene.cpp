// Scene loading: defaults, generators, and that each rejection names its field.
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "tests/support/catch.h"

#include "common/scene.h"

using cl::test::ContainsText;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {
cl::Scene parse(const std::string& text) { return cl::parse_scene(text, "test.json"); }

std::string rejection(const std::string& text) {
  try {
    parse(text);
  } catch (const cl::InputError& error) {
    return error.what();
  }
  return "(accepted)";
}
}  // namespace

TEST_CASE("explicit particles and springs with their defaults", "[common][scene]") {
  const cl::Scene scene = parse(R"({
    // comments are allowed
    "name": "two",
    "particles": [{"x": [0, 0, 0], "pinned": true}, {"x": [2, 0, 0], "v": [0, 1, 0], "mass": 4}],
    "springs": [{"i": 0, "j": 1}, {"i": 1, "j": 0, "rest": 0.5, "stiffness": 100}]
  })");
  CHECK(scene.name == "two");
  CHECK(scene.gravity == Eigen::Vector3d(0, -9.81, 0));
  CHECK_THAT(scene.dt, WithinRel(1.0 / 60.0, 1e-15));
  REQUIRE(scene.particles.size() == 2);
  CHECK(scene.particles.inv_mass[0] == 0.0);
  CHECK(scene.particles.inv_mass[1] == 0.25);
  CHECK(scene.particles.v.col(1) == Eigen::Vector3d(0, 1, 0));
  REQUIRE(scene.springs.size() == 2);
  CHECK(scene.springs[0].rest_length == 2.0);
  CHECK(std::isinf(scene.springs[0].stiffness));
  CHECK(scene.springs[1].rest_length == 0.5);
  CHECK(scene.springs[1].stiffness == 100.0);
  CHECK(scene.triangles.empty());
}

TEST_CASE("the chain generator", "[common][scene]") {
  const cl::Scene scene = parse(R"({"chain": {"links": 4, "length": 0.5, "mass": 2,
                                             "direction": [0, -2, 0], "pin": "both"}})");
  REQUIRE(scene.particles.size() == 5);
  REQUIRE(scene.springs.size() == 4);
  CHECK(scene.particles.x.col(4).isApprox(Eigen::Vector3d(0, -2, 0)));
  CHECK(scene.particles.inv_mass[0] == 0.0);
  CHECK(scene.particles.inv_mass[4] == 0.0);
  CHECK(scene.particles.inv_mass[2] == 0.5);
  for (const cl::Spring& spring : scene.springs) CHECK(spring.rest_length == 0.5);
  CHECK(scene.triangles.empty());
}

TEST_CASE("the cloth generator", "[common][scene]") {
  for (int n : {2, 3, 8}) {
    CAPTURE(n);
    const std::string text = R"({"cloth": {"nx": )" + std::to_string(n) + R"(, "ny": )" + std::to_string(n + 1) +
                             R"(, "width": 2, "height": 1, "mass": 3, "pin": ["top-left", "top-right"],
                                  "springs": ["structural", "shear", "bending"]}})";
    const cl::Scene scene = parse(text);
    const int nx = n, ny = n + 1;
    REQUIRE(scene.particles.size() == nx * ny);
    const auto structural = static_cast<std::size_t>((nx - 1) * ny + nx * (ny - 1));
    const auto shear = static_cast<std::size_t>(2 * (nx - 1) * (ny - 1));
    const auto bending = static_cast<std::size_t>(std::max(nx - 2, 0) * ny + nx * std::max(ny - 2, 0));
    CHECK(scene.springs.size() == structural + shear + bending);
    CHECK(scene.triangles.size() == static_cast<std::size_t>(2 * (nx - 1) * (ny - 1)));
    // Total mass 3, spread evenly; the top corners pinned; top = largest y.
    CHECK_THAT(scene.particles.inv_mass[nx], WithinRel(nx * ny / 3.0, 1e-14));
    CHECK(scene.particles.inv_mass[0] == 0.0);
    CHECK(scene.particles.inv_mass[nx - 1] == 0.0);
    CHECK(scene.particles.x(1, 0) == scene.particles.x.row(1).maxCoeff());
    double area = 0.0;
    for (const cl::Triangle& triangle : scene.triangles) area += triangle.rest_area;
    CHECK_THAT(area, WithinRel(2.0, 1e-12));
  }
  const cl::Scene flat = parse(R"({"cloth": {"nx": 3, "plane": "xz", "triangles": false}})");
  CHECK(flat.particles.x.row(1).isZero(0.0));
  CHECK(flat.triangles.empty());
}

TEST_CASE("jitter moves only free particles and keeps generated rest lengths", "[common][scene]") {
  const cl::Scene scene = parse(R"({"chain": {"links": 3}, "jitter": {"amplitude": 0.1, "seed": 5}})");
  CHECK(scene.particles.x.col(0) == Eigen::Vector3d::Zero());
  CHECK((scene.particles.x.col(1) - Eigen::Vector3d(1, 0, 0)).norm() > 0.0);
  CHECK((scene.particles.x.col(1) - Eigen::Vector3d(1, 0, 0)).cwiseAbs().maxCoeff() <= 0.1);
  CHECK(scene.springs[0].rest_length == 1.0);
  const cl::Scene again = parse(R"({"chain": {"links": 3}, "jitter": {"amplitude": 0.1, "seed": 5}})");
  CHECK(again.particles.x == scene.particles.x);
}

TEST_CASE("each rejection names the field and index", "[common][scene]") {
  CHECK_THAT(rejection("{"), ContainsText("test.json: malformed JSON"));
  CHECK_THAT(rejection(R"({"particles": [], "colour": 1})"), ContainsText("colour: unknown key"));
  CHECK_THAT(rejection(R"({"particles": [{"v": [0,0,0]}]})"), ContainsText("particles[0].x: missing"));
  CHECK_THAT(rejection(R"({"particles": [{"x": [0,0,0]}, {"x": [0,0,0], "mass": 0}]})"),
             ContainsText("particles[1].mass: must be in [1e-12, 1e12] kg (got 0)"));
  CHECK_THAT(rejection(R"({"particles": [{"x": [0,1e999,0]}]})"), ContainsText("particles[0].x[1]"));
  CHECK_THAT(rejection(R"({"particles": [{"x": [0,0,0]}, {"x": [1,0,0]}], "springs": [{"i": 0, "j": 2}]})"),
             ContainsText("springs[0].j: index out of range"));
  CHECK_THAT(rejection(R"({"particles": [{"x": [0,0,0]}, {"x": [1,0,0]}], "springs": [{"i": 0.5, "j": 1}]})"),
             ContainsText("springs[0].i: must be an integer"));
  CHECK_THAT(rejection(R"({"particles": [{"x": [0,0,0]}, {"x": [1,0,0]}], "springs": [{"i": 1, "j": 1}]})"),
             ContainsText("springs[0]: i and j must differ"));
  CHECK_THAT(rejection(R"({"particles": [{"x": [0,0,0]}, {"x": [1,0,0]}], "springs": [{"i": 0, "j": 1, "rest": -1}]})"),
             ContainsText("springs[0].rest: must be in [0, 1e6] m (got -1)"));
  CHECK_THAT(rejection(R"({"particles": [{"x": [0,0,0]}, {"x": [1,0,0]}], "springs": [{"i": 0, "j": 1, "stiffness": 0}]})"),
             ContainsText("springs[0].stiffness: must be a number in [1e-6, 1e15] N/m or \"inf\" (got 0)"));
  CHECK_THAT(rejection(R"({"particles": [{"x": [0,0,0]}, {"x": [1,0,0]}, {"x": [2,0,0]}], "triangles": [{"i": 0, "j": 1, "k": 2}]})"),
             ContainsText("triangles[0]: zero rest area"));
  CHECK_THAT(rejection(R"({"particles": [{"x": [0,0,0]}, {"x": [1,0,0]}, {"x": [0,1,0]}], "triangles": [{"i": 0, "j": 1, "k": 0}]})"),
             ContainsText("triangles[0]: repeated particle index"));
  CHECK_THAT(rejection(R"({"chain": {"links": 0}})"), ContainsText("chain.links"));
  CHECK_THAT(rejection(R"({"cloth": {"pin": ["middle"]}})"), ContainsText("cloth.pin[0]: must be one of"));
  CHECK_THAT(rejection(R"({"chain": {}, "cloth": {}})"), ContainsText("exactly one of"));
}

TEST_CASE("text nested a million deep is refused without a stack overflow", "[common][scene]") {
  // The sanitizer job found that a 20,000-deep array overflowed the stack
  // when the rejection printed it; a million deep crashed the Release build.
  const std::size_t depth = 1'000'000;
  const std::string text = std::string(depth, '[') + std::string(depth, ']');
  CHECK_THAT(rejection(text), ContainsText("nested deeper than 32 levels"));
  CHECK_THAT(rejection(R"({"particles": [{"x": [0,0,0], "v": [[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[0]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]}]})"),
             ContainsText("particles[0].v"));
}

TEST_CASE("rest length 0 is allowed", "[common][scene]") {
  const cl::Scene scene = parse(R"({"particles": [{"x": [0,0,0]}, {"x": [1,0,0]}], "springs": [{"i": 0, "j": 1, "rest": 0}]})");
  CHECK(scene.springs[0].rest_length == 0.0);
}

TEST_CASE("colliders are read with their defaults and a unit normal", "[common][scene]") {
  const cl::Scene scene = parse(R"({"particles": [{"x": [0,1,0]}], "colliders": [
      {"type": "plane", "point": [0,-1,0], "normal": [0,3,4], "friction": 0.5},
      {"type": "sphere", "centre": [1,2,3], "radius": 0.25},
      {"type": "capsule", "a": [0,0,0], "b": [1,0,0], "radius": 0.1, "friction": 0}]})");
  REQUIRE(scene.colliders.size() == 3);
  CHECK(scene.colliders[0].shape == cl::ColliderShape::kPlane);
  CHECK_THAT(scene.colliders[0].normal.y(), WithinAbs(0.6, 1e-15));
  CHECK_THAT(scene.colliders[0].normal.z(), WithinAbs(0.8, 1e-15));
  CHECK_THAT(scene.colliders[0].a.y(), WithinAbs(-1.0, 0.0));
  CHECK_THAT(scene.colliders[0].friction, WithinAbs(0.5, 0.0));
  CHECK(scene.colliders[1].shape == cl::ColliderShape::kSphere);
  CHECK_THAT(scene.colliders[1].radius, WithinAbs(0.25, 0.0));
  CHECK_THAT(scene.colliders[1].friction, WithinAbs(0.0, 0.0));  // the default: frictionless
  CHECK(scene.colliders[2].shape == cl::ColliderShape::kCapsule);
  CHECK_THAT(scene.colliders[2].b.x(), WithinAbs(1.0, 0.0));
  CHECK(std::string(cl::shape_name(scene.colliders[2].shape)) == "capsule");
  // A normal of huge components is scaled before it is normalised.
  const cl::Scene huge = parse(R"({"particles": [{"x": [0,1,0]}], "colliders": [
      {"type": "plane", "point": [0,0,0], "normal": [1e300,1e300,0]}]})");
  CHECK_THAT(huge.colliders[0].normal.norm(), WithinAbs(1.0, 1e-15));
  // No colliders: none.
  CHECK(parse(R"({"particles": [{"x": [0,0,0]}]})").colliders.empty());
}

TEST_CASE("each collider rejection names the field and index", "[common][scene]") {
  const std::string start = R"({"particles": [{"x": [0,0,0]}], "colliders": )";
  CHECK_THAT(rejection(start + R"({}})"), ContainsText("colliders: must be an array"));
  CHECK_THAT(rejection(start + R"([{"point": [0,0,0]}]})"), ContainsText("colliders[0].type: missing"));
  CHECK_THAT(rejection(start + R"([{"type": "cube"}]})"), ContainsText("colliders[0].type: must be one of"));
  CHECK_THAT(rejection(start + R"([{"type": "plane", "point": [0,0,0]}]})"), ContainsText("colliders[0].normal: missing"));
  CHECK_THAT(rejection(start + R"([{"type": "plane", "point": [0,0,0], "normal": [0,0,0]}]})"),
             ContainsText("colliders[0].normal: must not be the zero vector"));
  CHECK_THAT(rejection(start + R"([{"type": "plane", "point": [0,0,0], "normal": [0,1,0], "radius": 1}]})"),
             ContainsText("colliders[0].radius: unknown key"));
  CHECK_THAT(rejection(start + R"([{"type": "sphere", "centre": [0,0,0], "radius": 1},
                                   {"type": "sphere", "centre": [0,0,0], "radius": 0}]})"),
             ContainsText("colliders[1].radius: must be in (0, 1e6] m (got 0)"));
  CHECK_THAT(rejection(start + R"([{"type": "sphere", "centre": [0,0,0], "radius": 1, "friction": -0.1}]})"),
             ContainsText("colliders[0].friction: must be in [0, 1e9] (got -0.1)"));
  CHECK_THAT(rejection(start + R"([{"type": "capsule", "a": [0,0,0], "radius": 1}]})"),
             ContainsText("colliders[0].b: missing"));
  CHECK_THAT(rejection(start + R"([{"type": "capsule", "a": [-1.3e154,0,0], "b": [1.3e154,0,0], "radius": 1}]})"),
             ContainsText("colliders[0].a[0]: must be in [-1e6, 1e6] m"));
  CHECK_THAT(rejection(start + R"([{"type": "sphere", "centre": [1e308,1e308,0], "radius": 1}]})"),
             ContainsText("colliders[0].centre[0]: must be in [-1e6, 1e6] m"));
  CHECK_THAT(rejection(start + R"([{"type": "sphere", "centre": [0,"a",0], "radius": 1}]})"),
             ContainsText("colliders[0].centre[1]: must be a number"));
}

TEST_CASE("a range prints as a scene or a flag would write it", "[common][scene][limits]") {
  CHECK(cl::limits::kMass.text() == "[1e-12, 1e12] kg");
  CHECK(cl::limits::kLength.text() == "(0, 1e6] m");
  CHECK(cl::limits::kDt.text() == "[1e-9, 10] s");
  CHECK(cl::limits::kFriction.text() == "[0, 1e9]");
  CHECK(cl::limits::kLength.contains(1e6));
  CHECK_FALSE(cl::limits::kLength.contains(0.0));
  CHECK(cl::limits::kRest.contains(0.0));
  CHECK_FALSE(cl::limits::kMass.contains(std::nan("")));
}

// Finite numbers whose arithmetic overflows in a step (½ m v², k Δt²/m,
// x + v Δt, a length's fourth power): each refused by its field, with the
// range it must lie in (docs/DESIGN.md §3).
TEST_CASE("a finite number outside its range is refused naming the field and the range", "[common][scene][limits]") {
  const std::string one = R"("particles": [{"x": [0,0,0]}])";
  const std::string two = R"("particles": [{"x": [0,0,0]}, {"x": [1,0,0]}])";
  const std::string sphere = R"({"particles": [{"x": [0,0,0]}], "colliders": [{"type": "sphere", "centre": [0,0,0], )";
  const std::vector<std::pair<std::string, std::string>> cases{
      {R"({"particles": [{"x": [0,0,0], "mass": 1e160}]})", "particles[0].mass: must be in [1e-12, 1e12] kg (got 1e+160)"},
      {R"({"particles": [{"x": [0,0,0]}, {"x": [1,0,0], "mass": 1e-13}]})", "particles[1].mass: must be in [1e-12, 1e12] kg"},
      {R"({"particles": [{"x": [0,0,0], "mass": 1e-320}]})", "particles[0].mass: must be in [1e-12, 1e12] kg"},
      {R"({"particles": [{"x": [0,0,0], "v": [0,1e300,0]}]})", "particles[0].v[1]: must be in [-1e8, 1e8] m/s (got 1e+300)"},
      {R"({"particles": [{"x": [0,0,0], "v": [-1e300,0,0]}]})", "particles[0].v[0]: must be in [-1e8, 1e8] m/s"},
      {R"({"particles": [{"x": [0,0,0]}, {"x": [0,0,1e300]}]})", "particles[1].x[2]: must be in [-1e6, 1e6] m"},
      {R"({"particles": [{"x": [0,0,0]}, {"x": [1e200,0,0]}], "springs": [{"i": 0, "j": 1}]})",
       "particles[1].x[0]: must be in [-1e6, 1e6] m"},
      {"{" + two + R"(, "springs": [{"i": 0, "j": 1, "rest": 1e300}]})", "springs[0].rest: must be in [0, 1e6] m"},
      {"{" + two + R"(, "springs": [{"i": 0, "j": 1, "stiffness": 1e300}]})", "springs[0].stiffness: must be a number in [1e-6, 1e15] N/m"},
      {"{" + two + R"(, "springs": [{"i": 0, "j": 1, "stiffness": 1e-300}]})", "springs[0].stiffness: must be a number in [1e-6, 1e15] N/m"},
      {"{" + one + R"(, "gravity": [0, -1e300, 0]})", "gravity[1]: must be in [-1e6, 1e6] m/s²"},
      {"{" + one + R"(, "dt": 1e300})", "dt: must be in [1e-9, 10] s (got 1e+300)"},
      {"{" + one + R"(, "dt": 1e-300})", "dt: must be in [1e-9, 10] s"},
      {"{" + one + R"(, "steps": 1e12})", "steps: must be an integer in [0, 100000000]"},
      {"{" + one + R"(, "steps": 100000001})", "steps: must be an integer in [0, 100000000]"},
      {"{" + one + R"(, "steps": 2.5})", "steps: must be an integer (got 2.5)"},
      {sphere + R"("radius": 1e308}]})", "colliders[0].radius: must be in (0, 1e6] m (got 1e+308)"},
      {sphere + R"("radius": 1, "friction": 1e300}]})", "colliders[0].friction: must be in [0, 1e9]"},
      {R"({"particles": [{"x": [0,0,0]}], "colliders": [{"type": "plane", "point": [0,-1e300,0], "normal": [0,1,0]}]})",
       "colliders[0].point[1]: must be in [-1e6, 1e6] m"},
      {R"({"cloth": {"nx": 4, "mass": 1e160}})", "cloth.mass: must be in [1e-12, 1e12] kg"},
      {R"({"cloth": {"nx": 4, "width": 1e300}})", "cloth.width: must be in (0, 1e6] m"},
      {R"({"cloth": {"nx": 4, "height": 2e6}})", "cloth.height: must be in (0, 1e6] m"},
      {R"({"cloth": {"nx": 4, "stiffness": 1e16}})", "cloth.stiffness: must be a number in [1e-6, 1e15] N/m"},
      {R"({"chain": {"links": 2, "length": 1e300}})", "chain.length: must be in (0, 1e6] m"},
      {R"({"chain": {"links": 2, "mass": 1e160}})", "chain.mass: must be in [1e-12, 1e12] kg"},
      {R"({"chain": {"links": 2, "origin": [1e300, 0, 0]}})", "chain.origin[0]: must be in [-1e6, 1e6] m"},
      // Each field in range, the particles they place not: named by what placed them.
      {R"({"chain": {"links": 2000, "length": 1000}})", "chain: places particle 1001 at 1.001e+06 m on axis 0"},
      {R"({"chain": {"links": 2, "pin": "none"}, "jitter": {"amplitude": 1e300}})", "jitter.amplitude: must be in [0, 1e6] m"},
      {R"({"particles": [{"x": [1e6,1e6,1e6]}], "jitter": {"amplitude": 1e6, "seed": 3}})",
       "jitter.amplitude: places particle 0 at"},
  };
  for (const auto& [text, expected] : cases) {
    CAPTURE(text);
    CHECK_THAT(rejection(text), ContainsText("test.json: " + expected));
  }
}

TEST_CASE("the ranges' own ends are accepted, and an integer may be written 1e2", "[common][scene][limits]") {
  const cl::Scene low = parse(R"({"dt": 1e-9, "steps": 1e2, "gravity": [-1e6, 0, 1e6],
      "particles": [{"x": [-1e6, 0, 1e6], "v": [1e8, -1e8, 0], "mass": 1e-12}, {"x": [1e6, 0, 0], "mass": 1e12}],
      "springs": [{"i": 0, "j": 1, "stiffness": 1e-6}, {"i": 1, "j": 0, "stiffness": 1e15, "rest": 1e6}],
      "colliders": [{"type": "sphere", "centre": [1e6, 1e6, 1e6], "radius": 1e6, "friction": 1e9}]})");
  CHECK(low.dt == 1e-9);
  CHECK(low.steps == 100);
  CHECK(low.particles.inv_mass[0] == 1e12);
  CHECK(low.springs[0].rest_length == Approx(std::sqrt(5.0) * 1e6));  // the default: the initial distance
  const cl::Scene high = parse(R"({"dt": 10, "steps": 100000000, "chain": {"links": 1048576, "length": 0.9, "origin": [-1e6, 0, 0]}})");
  CHECK(high.dt == 10.0);
  CHECK(high.particles.size() == 1048577);
  // A direction of tiny components is scaled before it is normalised, as a huge one.
  const cl::Scene tiny = parse(R"({"chain": {"links": 1, "direction": [0, 1e-300, 0]}})");
  CHECK_THAT(tiny.particles.x(1, 1), WithinAbs(1.0, 1e-15));
}

TEST_CASE("a folder given as the scene is named a folder, not malformed JSON", "[common][scene]") {
  const std::string folder = std::string(CL_SOURCE_DIR) + "/labs";
  CHECK_THROWS_WITH(cl::load_scene(folder), folder + ": is a folder, not a scene file (give a .json file or a scene name)");
}
