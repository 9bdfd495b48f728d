#include "common/scene.h"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "common/source_dir.h"

namespace cl {

namespace {

using nlohmann::json;
namespace fs = std::filesystem;

std::string show(const json& value) {
  std::string text = value.dump();
  // An integer written as a float dumps as "1000000000000.0": shown without the ".0".
  if (value.is_number_float() && text.size() > 2 && text.compare(text.size() - 2, 2, ".0") == 0) {
    text.resize(text.size() - 2);
  }
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return text;
}

// Validation with error messages of the form "file: field[index].key: problem".
class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const std::string& field, const std::string& problem) const {
    throw InputError(source_ + ": " + field + ": " + problem);
  }

  void require_object(const json& value, const std::string& field) const {
    if (!value.is_object()) fail(field, "must be an object (got " + show(value) + ")");
  }

  void check_keys(const json& object, const std::set<std::string>& allowed,
                  const std::string& field) const {
    for (const auto& item : object.items()) {
      if (allowed.count(item.key()) == 0) {
        std::string known;
        for (const std::string& key : allowed) known += (known.empty() ? "" : ", ") + key;
        fail(join(field, item.key()), "unknown key (allowed: " + known + ")");
      }
    }
  }

  static std::string join(const std::string& field, const std::string& key) {
    return field.empty() ? key : field + "." + key;
  }

  double number(const json& value, const std::string& field) const {
    if (!value.is_number()) fail(field, "must be a number (got " + show(value) + ")");
    const double result = value.get<double>();
    if (!std::isfinite(result)) fail(field, "must be finite (got " + show(value) + ")");
    return result;
  }

  // A number in `range` (limits in scene.h): finite is not enough, since a
  // mass of 1e160 or a speed of 1e300 overflows the first step's arithmetic.
  double in(const json& value, const std::string& field, const Range& range) const {
    const double result = number(value, field);
    if (!range.contains(result)) fail(field, "must be in " + range.text() + " (got " + show(value) + ")");
    return result;
  }

  // An integer's value as a double: a JSON integer, or a number such as 1e12
  // or 2.0 that is one (JSON has a single number type), so that a value out
  // of range is told its range rather than that it is not an integer.
  double whole(const json& value, const std::string& field) const {
    if (value.is_number_unsigned()) return static_cast<double>(value.get<std::uint64_t>());
    if (value.is_number_integer()) return static_cast<double>(value.get<std::int64_t>());
    if (value.is_number_float()) {
      const double result = value.get<double>();
      if (std::isfinite(result) && result == std::trunc(result)) return result;
    }
    fail(field, "must be an integer (got " + show(value) + ")");
  }

  int integer_in(const json& value, const std::string& field, int low, int high) const {
    const double result = whole(value, field);
    if (result < low || result > high) {
      fail(field, "must be an integer in [" + std::to_string(low) + ", " + std::to_string(high) +
                      "] (got " + show(value) + ")");
    }
    return static_cast<int>(result);
  }

  int index(const json& value, const std::string& field, Eigen::Index count) const {
    const double result = whole(value, field);
    if (result < 0.0 || result >= static_cast<double>(count)) {
      fail(field, "index out of range [0, " + std::to_string(count) + ") (got " + show(value) + ")");
    }
    return static_cast<int>(result);
  }

  // Three numbers, each in `range` when one is given.
  Eigen::Vector3d vec3(const json& value, const std::string& field, const Range* range = nullptr) const {
    if (!value.is_array() || value.size() != 3) {
      fail(field, "must be an array of 3 numbers (got " + show(value) + ")");
    }
    Eigen::Vector3d result;
    for (int axis = 0; axis < 3; ++axis) {
      const json& component = value[static_cast<std::size_t>(axis)];
      const std::string name = field + "[" + std::to_string(axis) + "]";
      result[axis] = range ? in(component, name, *range) : number(component, name);
    }
    return result;
  }

  // A direction: any non-zero vector of finite numbers, returned with length 1.
  Eigen::Vector3d direction(const json& value, const std::string& field) const {
    Eigen::Vector3d result = vec3(value, field);
    const double largest = result.cwiseAbs().maxCoeff();
    if (!(largest > 0.0)) fail(field, "must not be the zero vector");
    result /= largest;  // scaled first, so that 1e300s do not overflow the norm nor 1e-300s underflow it
    return result.normalized();
  }

  bool boolean(const json& value, const std::string& field) const {
    if (!value.is_boolean()) fail(field, "must be true or false (got " + show(value) + ")");
    return value.get<bool>();
  }

  std::string string(const json& value, const std::string& field) const {
    if (!value.is_string()) fail(field, "must be a string (got " + show(value) + ")");
    return value.get<std::string>();
  }

  std::string one_of(const json& value, const std::string& field,
                     const std::vector<std::string>& choices) const {
    const std::string result = string(value, field);
    if (std::find(choices.begin(), choices.end(), result) == choices.end()) {
      std::string known;
      for (const std::string& choice : choices) known += (known.empty() ? "" : ", ") + choice;
      fail(field, "must be one of " + known + " (got " + show(value) + ")");
    }
    return result;
  }

  // Stiffness in N/m: a number in limits::kStiffness or the string "inf" (a hard constraint).
  double stiffness(const json& value, const std::string& field) const {
    const std::string wanted = "must be a number in " + limits::kStiffness.text() + " or \"inf\" (got " + show(value) + ")";
    if (value.is_string() && value.get<std::string>() == "inf") return kInfiniteStiffness;
    if (!value.is_number()) fail(field, wanted);
    const double result = number(value, field);
    if (!limits::kStiffness.contains(result)) fail(field, wanted);
    return result;
  }

  const json& array(const json& value, const std::string& field) const {
    if (!value.is_array()) fail(field, "must be an array (got " + show(value) + ")");
    return value;
  }

 private:
  std::string source_;
};

std::string item(const std::string& field, std::size_t index) {
  return field + "[" + std::to_string(index) + "]";
}

void resize_particles(Particles& particles, Eigen::Index n) {
  particles.x.setZero(3, n);
  particles.v.setZero(3, n);
  particles.inv_mass.setZero(n);
}

void read_particles(const Reader& reader, const json& list, Scene& scene) {
  reader.array(list, "particles");
  resize_particles(scene.particles, static_cast<Eigen::Index>(list.size()));
  for (std::size_t p = 0; p < list.size(); ++p) {
    const std::string field = item("particles", p);
    const json& entry = list[p];
    reader.require_object(entry, field);
    reader.check_keys(entry, {"x", "v", "mass", "pinned"}, field);
    if (!entry.contains("x")) reader.fail(field + ".x", "missing (every particle needs a position)");
    const auto n = static_cast<Eigen::Index>(p);
    scene.particles.x.col(n) = reader.vec3(entry["x"], field + ".x", &limits::kCoordinate);
    if (entry.contains("v")) scene.particles.v.col(n) = reader.vec3(entry["v"], field + ".v", &limits::kVelocity);
    const double mass = entry.contains("mass") ? reader.in(entry["mass"], field + ".mass", limits::kMass) : 1.0;
    const bool pinned = entry.contains("pinned") && reader.boolean(entry["pinned"], field + ".pinned");
    scene.particles.inv_mass[n] = pinned ? 0.0 : 1.0 / mass;
  }
}

void read_springs(const Reader& reader, const json& list, Scene& scene) {
  reader.array(list, "springs");
  const Eigen::Index n = scene.particles.size();
  for (std::size_t s = 0; s < list.size(); ++s) {
    const std::string field = item("springs", s);
    const json& entry = list[s];
    reader.require_object(entry, field);
    reader.check_keys(entry, {"i", "j", "rest", "stiffness"}, field);
    if (!entry.contains("i")) reader.fail(field + ".i", "missing");
    if (!entry.contains("j")) reader.fail(field + ".j", "missing");
    Spring spring;
    spring.i = reader.index(entry["i"], field + ".i", n);
    spring.j = reader.index(entry["j"], field + ".j", n);
    if (spring.i == spring.j) reader.fail(field, "i and j must differ (both " + std::to_string(spring.i) + ")");
    spring.rest_length = entry.contains("rest")
                             ? reader.in(entry["rest"], field + ".rest", limits::kRest)
                             : (scene.particles.x.col(spring.i) - scene.particles.x.col(spring.j)).norm();
    if (entry.contains("stiffness")) spring.stiffness = reader.stiffness(entry["stiffness"], field + ".stiffness");
    scene.springs.push_back(spring);
  }
}

double triangle_area(const Eigen::Matrix3Xd& x, int i, int j, int k) {
  const Eigen::Vector3d e1 = x.col(j) - x.col(i);
  const Eigen::Vector3d e2 = x.col(k) - x.col(i);
  return 0.5 * e1.cross(e2).norm();
}

// Zero area up to round-off, relative to the triangle's size.
bool degenerate_area(const Eigen::Matrix3Xd& x, int i, int j, int k, double area) {
  const double longest = std::max({(x.col(i) - x.col(j)).squaredNorm(),
                                   (x.col(j) - x.col(k)).squaredNorm(),
                                   (x.col(k) - x.col(i)).squaredNorm()});
  return !(area > 1e-12 * longest);
}

void read_triangles(const Reader& reader, const json& list, Scene& scene) {
  reader.array(list, "triangles");
  const Eigen::Index n = scene.particles.size();
  for (std::size_t t = 0; t < list.size(); ++t) {
    const std::string field = item("triangles", t);
    const json& entry = list[t];
    reader.require_object(entry, field);
    reader.check_keys(entry, {"i", "j", "k"}, field);
    Triangle triangle;
    for (const char* key : {"i", "j", "k"}) {
      if (!entry.contains(key)) reader.fail(field + "." + key, "missing");
    }
    triangle.i = reader.index(entry["i"], field + ".i", n);
    triangle.j = reader.index(entry["j"], field + ".j", n);
    triangle.k = reader.index(entry["k"], field + ".k", n);
    if (triangle.i == triangle.j || triangle.j == triangle.k || triangle.k == triangle.i) {
      reader.fail(field, "repeated particle index (" + std::to_string(triangle.i) + ", " +
                             std::to_string(triangle.j) + ", " + std::to_string(triangle.k) + ")");
    }
    triangle.rest_area = triangle_area(scene.particles.x, triangle.i, triangle.j, triangle.k);
    if (degenerate_area(scene.particles.x, triangle.i, triangle.j, triangle.k, triangle.rest_area)) {
      reader.fail(field, "zero rest area (its three particles are collinear or coincident)");
    }
    scene.triangles.push_back(triangle);
  }
}

void add_spring(Scene& scene, int i, int j, double stiffness) {
  const double rest = (scene.particles.x.col(i) - scene.particles.x.col(j)).norm();
  scene.springs.push_back(Spring{i, j, rest, stiffness});
}

void generate_cloth(const Reader& reader, const json& cloth, Scene& scene) {
  const std::string field = "cloth";
  reader.require_object(cloth, field);
  reader.check_keys(cloth, {"nx", "ny", "width", "height", "mass", "pin", "springs", "stiffness",
                            "plane", "triangles"},
                    field);
  auto get = [&](const char* key) -> const json* { return cloth.contains(key) ? &cloth[key] : nullptr; };
  const int nx = get("nx") ? reader.integer_in(*get("nx"), "cloth.nx", 2, limits::kMaxClothSide) : 16;
  const int ny = get("ny") ? reader.integer_in(*get("ny"), "cloth.ny", 2, limits::kMaxClothSide) : nx;
  // Within ±width/2 across and [0, height] up: inside limits::kCoordinate.
  const double width = get("width") ? reader.in(*get("width"), "cloth.width", limits::kLength) : 1.0;
  const double height = get("height") ? reader.in(*get("height"), "cloth.height", limits::kLength) : 1.0;
  const double mass = get("mass") ? reader.in(*get("mass"), "cloth.mass", limits::kMass) : 1.0;
  const double stiffness = get("stiffness") ? reader.stiffness(*get("stiffness"), "cloth.stiffness")
                                            : kInfiniteStiffness;
  const std::string plane = get("plane") ? reader.one_of(*get("plane"), "cloth.plane", {"xy", "xz"}) : "xy";
  const bool with_triangles = get("triangles") ? reader.boolean(*get("triangles"), "cloth.triangles") : true;

  const Eigen::Index count = static_cast<Eigen::Index>(nx) * ny;
  resize_particles(scene.particles, count);
  scene.particles.inv_mass.setConstant(static_cast<double>(count) / mass);
  auto id = [nx](int row, int col) { return row * nx + col; };
  // Row 0 is the top edge (largest y, or largest z in the xz plane), column 0 the left.
  for (int row = 0; row < ny; ++row) {
    for (int col = 0; col < nx; ++col) {
      const double across = -0.5 * width + width * col / (nx - 1);
      const double up = height * (ny - 1 - row) / (ny - 1);
      scene.particles.x.col(id(row, col)) =
          plane == "xy" ? Eigen::Vector3d(across, up, 0.0) : Eigen::Vector3d(across, 0.0, up);
    }
  }
  scene.grid_nx = nx;
  scene.grid_ny = ny;

  if (get("pin")) {
    const json& pins = reader.array(*get("pin"), "cloth.pin");
    for (std::size_t p = 0; p < pins.size(); ++p) {
      const std::string where = reader.one_of(
          pins[p], item("cloth.pin", p), {"top-left", "top-right", "bottom-left", "bottom-right", "top"});
      if (where == "top") {
        for (int col = 0; col < nx; ++col) scene.particles.inv_mass[id(0, col)] = 0.0;
      } else {
        const int row = where.rfind("top", 0) == 0 ? 0 : ny - 1;
        const int col = where.find("left") != std::string::npos ? 0 : nx - 1;
        scene.particles.inv_mass[id(row, col)] = 0.0;
      }
    }
  }

  std::vector<std::string> kinds{"structural", "shear"};
  if (get("springs")) {
    kinds.clear();
    const json& list = reader.array(*get("springs"), "cloth.springs");
    for (std::size_t s = 0; s < list.size(); ++s) {
      kinds.push_back(reader.one_of(list[s], item("cloth.springs", s), {"structural", "shear", "bending"}));
    }
  }
  auto wants = [&](const char* kind) { return std::find(kinds.begin(), kinds.end(), kind) != kinds.end(); };
  for (int row = 0; row < ny; ++row) {
    for (int col = 0; col < nx; ++col) {
      if (wants("structural")) {
        if (col + 1 < nx) add_spring(scene, id(row, col), id(row, col + 1), stiffness);
        if (row + 1 < ny) add_spring(scene, id(row, col), id(row + 1, col), stiffness);
      }
      if (wants("shear") && col + 1 < nx && row + 1 < ny) {
        add_spring(scene, id(row, col), id(row + 1, col + 1), stiffness);
        add_spring(scene, id(row, col + 1), id(row + 1, col), stiffness);
      }
      if (wants("bending")) {
        if (col + 2 < nx) add_spring(scene, id(row, col), id(row, col + 2), stiffness);
        if (row + 2 < ny) add_spring(scene, id(row, col), id(row + 2, col), stiffness);
      }
    }
  }
  if (with_triangles) {
    for (int row = 0; row + 1 < ny; ++row) {
      for (int col = 0; col + 1 < nx; ++col) {
        const int a = id(row, col), b = id(row, col + 1), c = id(row + 1, col), d = id(row + 1, col + 1);
        for (const auto& [i, j, k] : {std::array<int, 3>{a, c, b}, std::array<int, 3>{b, c, d}}) {
          scene.triangles.push_back(Triangle{i, j, k, triangle_area(scene.particles.x, i, j, k)});
        }
      }
    }
  }
  // A width or height so small for nx, ny that a cell's area underflows to 0
  // in double precision (an overflow cannot happen: width, height <= 1e6 m): the
  // smaller spacing is named.
  const bool areas_ok = std::all_of(scene.triangles.begin(), scene.triangles.end(),
                                    [](const Triangle& triangle) { return triangle.rest_area != 0.0; });
  if (!areas_ok) {
    const bool across = width / (nx - 1) <= height / (ny - 1);
    reader.fail(across ? "cloth.width" : "cloth.height",
                std::string("too small for ") + (across ? "nx = " + std::to_string(nx) : "ny = " + std::to_string(ny)) +
                    ": its triangles' rest areas underflow to 0 in double precision");
  }
}

void generate_chain(const Reader& reader, const json& chain, Scene& scene) {
  reader.require_object(chain, "chain");
  reader.check_keys(chain, {"links", "length", "mass", "direction", "origin", "pin", "stiffness"}, "chain");
  auto get = [&](const char* key) -> const json* { return chain.contains(key) ? &chain[key] : nullptr; };
  const int links = get("links") ? reader.integer_in(*get("links"), "chain.links", 1, limits::kMaxChainLinks) : 10;
  const double length = get("length") ? reader.in(*get("length"), "chain.length", limits::kLength) : 1.0;
  const double mass = get("mass") ? reader.in(*get("mass"), "chain.mass", limits::kMass) : 1.0;
  const Eigen::Vector3d direction =
      get("direction") ? reader.direction(*get("direction"), "chain.direction") : Eigen::Vector3d(1.0, 0.0, 0.0);
  const Eigen::Vector3d origin =
      get("origin") ? reader.vec3(*get("origin"), "chain.origin", &limits::kCoordinate) : Eigen::Vector3d::Zero();
  const std::string pin = get("pin") ? reader.one_of(*get("pin"), "chain.pin", {"first", "last", "both", "none"}) : "first";
  const double stiffness = get("stiffness") ? reader.stiffness(*get("stiffness"), "chain.stiffness") : kInfiniteStiffness;

  resize_particles(scene.particles, links + 1);
  scene.particles.inv_mass.setConstant(1.0 / mass);
  for (int p = 0; p <= links; ++p) scene.particles.x.col(p) = origin + (length * p) * direction;
  if (pin == "first" || pin == "both") scene.particles.inv_mass[0] = 0.0;
  if (pin == "last" || pin == "both") scene.particles.inv_mass[links] = 0.0;
  for (int p = 0; p < links; ++p) scene.springs.push_back(Spring{p, p + 1, length, stiffness});
}

// Deterministic, platform-independent uniform numbers in [-1, 1) (splitmix64).
double next_symmetric(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  z ^= z >> 31;
  return 2.0 * static_cast<double>(z >> 11) * 0x1.0p-53 - 1.0;
}

void apply_jitter(const Reader& reader, const json& jitter, Scene& scene) {
  reader.require_object(jitter, "jitter");
  reader.check_keys(jitter, {"amplitude", "seed"}, "jitter");
  const double amplitude = jitter.contains("amplitude") ? reader.in(jitter["amplitude"], "jitter.amplitude", limits::kRest) : 0.0;
  std::uint64_t state = jitter.contains("seed")
                            ? static_cast<std::uint64_t>(reader.integer_in(jitter["seed"], "jitter.seed", 0, 2'000'000'000))
                            : 1u;
  for (Eigen::Index p = 0; p < scene.particles.size(); ++p) {
    for (int axis = 0; axis < 3; ++axis) {
      const double offset = amplitude * next_symmetric(state);
      if (scene.particles.inv_mass[p] > 0.0) scene.particles.x(axis, p) += offset;
    }
  }
}

// Colliders (lab 14): a list of planes, spheres and capsules, each with its
// own keys and a friction coefficient. Points lie in limits::kCoordinate, as
// the particles do: the contact tests take norms of their differences.
void read_colliders(const Reader& reader, const json& list, Scene& scene) {
  reader.array(list, "colliders");
  for (std::size_t c = 0; c < list.size(); ++c) {
    const std::string field = item("colliders", c);
    const json& entry = list[c];
    reader.require_object(entry, field);
    if (!entry.contains("type")) reader.fail(field + ".type", "missing (plane, sphere or capsule)");
    const std::string type = reader.one_of(entry["type"], field + ".type", {"plane", "sphere", "capsule"});
    Collider collider;
    std::vector<std::string> needed;
    if (type == "plane") {
      collider.shape = ColliderShape::kPlane;
      needed = {"point", "normal"};
    } else if (type == "sphere") {
      collider.shape = ColliderShape::kSphere;
      needed = {"centre", "radius"};
    } else {
      collider.shape = ColliderShape::kCapsule;
      needed = {"a", "b", "radius"};
    }
    std::set<std::string> allowed{"type", "friction"};
    allowed.insert(needed.begin(), needed.end());
    reader.check_keys(entry, allowed, field);
    for (const std::string& key : needed) {
      if (!entry.contains(key)) reader.fail(field + "." + key, "missing (a " + type + " needs it)");
    }
    auto point = [&](const char* key) {
      return reader.vec3(entry[key], field + "." + key, &limits::kCoordinate);
    };
    if (collider.shape == ColliderShape::kPlane) {
      collider.a = point("point");
      collider.normal = reader.direction(entry["normal"], field + ".normal");
    } else {
      collider.a = point(collider.shape == ColliderShape::kSphere ? "centre" : "a");
      collider.b = collider.shape == ColliderShape::kCapsule ? point("b") : collider.a;
      collider.radius = reader.in(entry["radius"], field + ".radius", limits::kLength);
    }
    collider.friction = entry.contains("friction") ? reader.in(entry["friction"], field + ".friction", limits::kFriction) : 0.0;
    scene.colliders.push_back(collider);
  }
}

// Builds the document like nlohmann's own parser while tracking where it is,
// so that a number too large for a double (JSON has no inf) is reported with
// its field and index like every other rejection.
class TrackingBuilder : public nlohmann::json_sax<json> {
 public:
  TrackingBuilder(json& root, std::string source) : dom_(root, false), source_(std::move(source)) {}

  bool null() override { return value(dom_.null()); }
  bool boolean(bool v) override { return value(dom_.boolean(v)); }
  bool number_integer(number_integer_t v) override { return value(dom_.number_integer(v)); }
  bool number_unsigned(number_unsigned_t v) override { return value(dom_.number_unsigned(v)); }
  bool number_float(number_float_t v, const string_t& s) override { return value(dom_.number_float(v, s)); }
  bool string(string_t& v) override { return value(dom_.string(v)); }
  bool binary(binary_t& v) override { return value(dom_.binary(v)); }
  bool start_object(std::size_t n) override { return open(false) && dom_.start_object(n); }
  bool key(string_t& k) override {
    path_.back().key = k;
    // JSON parsers keep one of two equal keys silently; a scene says it once.
    if (!path_.back().keys.insert(k).second) throw InputError(source_ + ": " + here() + ": duplicate key");
    return dom_.key(k);
  }
  bool end_object() override { return close() && dom_.end_object(); }
  bool start_array(std::size_t n) override { return open(true) && dom_.start_array(n); }
  bool end_array() override { return close() && dom_.end_array(); }
  bool parse_error(std::size_t position, const std::string& token, const nlohmann::detail::exception& error) override {
    if (error.id == 406) {  // number overflow: the value was read, so the path is known
      throw InputError(source_ + ": " + here() + ": must be finite (got " + token + ")");
    }
    std::string what = error.what();
    const std::size_t at = what.find("] ");
    if (at != std::string::npos) what = what.substr(at + 2);
    (void)position;
    throw InputError(source_ + ": malformed JSON: " + what);
  }

 private:
  struct Level {
    bool array = false;
    long index = -1;
    std::string key;
    std::set<std::string> keys;  // an object's keys so far
  };

  bool open(bool array) {
    // A scene nests 4 deep (top, particles, one particle, x). Deeper text is
    // refused while it is read: printing or freeing a value nested a million
    // deep recurses once per level and overflows the stack.
    if (path_.size() >= kMaxNesting) {
      throw InputError(source_ + ": " + here() + ": nested deeper than " + std::to_string(kMaxNesting) +
                       " levels (a scene needs 4)");
    }
    before_value();
    path_.push_back(Level{array, -1, {}, {}});
    return true;
  }
  bool close() {
    path_.pop_back();
    return true;
  }
  void before_value() {
    if (!path_.empty() && path_.back().array) ++path_.back().index;
  }
  bool value(bool accepted) {
    before_value();
    return accepted;
  }
  // The field being read, in the form the other messages use: "particles[3].x[2]".
  std::string here() const {
    // The failing number was never counted, so the innermost array is one behind.
    std::string field;
    for (std::size_t depth = 0; depth < path_.size(); ++depth) {
      const Level& level = path_[depth];
      if (level.array) {
        field += "[" + std::to_string(level.index + (depth + 1 == path_.size() ? 1 : 0)) + "]";
      } else if (!level.key.empty()) {
        field += (field.empty() ? "" : ".") + level.key;
      }
    }
    return field.empty() ? "(top level)" : field;
  }

  static constexpr std::size_t kMaxNesting = 32;

  nlohmann::detail::json_sax_dom_parser<json> dom_;
  std::string source_;
  std::vector<Level> path_;
};

// A generator or the jitter can place particles past limits::kCoordinate
// from fields that are each in range (a chain of 1024² links of 1 km, a
// jitter of 1e6 m around a point 1e6 m out). `field` names what placed them.
void check_positions(const Reader& reader, const Scene& scene, const std::string& field) {
  const Eigen::Matrix3Xd& x = scene.particles.x;
  for (Eigen::Index p = 0; p < x.cols(); ++p) {
    for (int axis = 0; axis < 3; ++axis) {
      if (!limits::kCoordinate.contains(x(axis, p))) {
        std::ostringstream where;
        where << x(axis, p);
        reader.fail(field, "places particle " + std::to_string(p) + " at " + where.str() + " m on axis " +
                               std::to_string(axis) + ", outside " + limits::kCoordinate.text());
      }
    }
  }
}

}  // namespace

Scene parse_scene(const std::string& text, const std::string& source) {
  json root;
  TrackingBuilder builder(root, source);
  json::sax_parse(text, &builder, json::input_format_t::json, /*strict=*/true, /*ignore_comments=*/true);
  const Reader reader(source);
  reader.require_object(root, "(top level)");
  reader.check_keys(root, {"name", "description", "gravity", "dt", "steps", "particles", "springs",
                           "triangles", "cloth", "chain", "jitter", "colliders"},
                    "");

  Scene scene;
  scene.source = source;
  scene.name = root.contains("name") ? reader.string(root["name"], "name") : fs::path(source).stem().string();
  if (root.contains("description")) reader.string(root["description"], "description");
  if (root.contains("gravity")) scene.gravity = reader.vec3(root["gravity"], "gravity", &limits::kGravity);
  if (root.contains("dt")) scene.dt = reader.in(root["dt"], "dt", limits::kDt);
  if (root.contains("steps")) scene.steps = reader.integer_in(root["steps"], "steps", 0, limits::kMaxSteps);

  const int sources = static_cast<int>(root.contains("particles")) + static_cast<int>(root.contains("cloth")) +
                      static_cast<int>(root.contains("chain"));
  if (sources != 1) {
    reader.fail("particles", "a scene needs exactly one of \"particles\", \"cloth\" or \"chain\" (found " +
                                 std::to_string(sources) + ")");
  }
  if (root.contains("particles")) {
    read_particles(reader, root["particles"], scene);
    if (root.contains("springs")) read_springs(reader, root["springs"], scene);
    if (root.contains("triangles")) read_triangles(reader, root["triangles"], scene);
  } else {
    for (const char* key : {"springs", "triangles"}) {
      if (root.contains(key)) reader.fail(key, "not allowed with a generator (it makes its own)");
    }
    if (root.contains("cloth")) generate_cloth(reader, root["cloth"], scene);
    if (root.contains("chain")) generate_chain(reader, root["chain"], scene);
  }
  if (root.contains("chain")) check_positions(reader, scene, "chain");
  if (root.contains("jitter")) {
    apply_jitter(reader, root["jitter"], scene);
    check_positions(reader, scene, "jitter.amplitude");
  }
  if (root.contains("colliders")) read_colliders(reader, root["colliders"], scene);
  return scene;
}

Scene load_scene(const std::string& path) {
  std::error_code error;
  // A folder opens as a stream on Linux and reads as empty text, which would
  // be reported as malformed JSON.
  if (fs::is_directory(path, error)) throw InputError(path + ": is a folder, not a scene file (give a .json file or a scene name)");
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path + ": cannot open scene file");
  std::ostringstream text;
  text << file.rdbuf();
  return parse_scene(text.str(), path);
}

std::string resolve_scene_path(const std::string& name_or_path, const std::string& lab_scene_dir,
                               const std::string& flag) {
  std::error_code error;
  const bool looks_like_path = name_or_path.find('/') != std::string::npos ||
                               (name_or_path.size() > 5 && name_or_path.substr(name_or_path.size() - 5) == ".json");
  if (looks_like_path || fs::is_regular_file(name_or_path, error)) return name_or_path;

  std::vector<fs::path> places{fs::path(lab_scene_dir)};
  const fs::path labs = fs::path(source_dir()) / "labs";
  if (fs::is_directory(labs, error)) {
    std::vector<fs::path> lab_dirs;
    for (const auto& entry : fs::directory_iterator(labs, error)) lab_dirs.push_back(entry.path() / "scenes");
    std::sort(lab_dirs.begin(), lab_dirs.end());
    places.insert(places.end(), lab_dirs.begin(), lab_dirs.end());
  }
  for (const fs::path& place : places) {
    const fs::path candidate = place / (name_or_path + ".json");
    if (fs::is_regular_file(candidate, error)) return candidate.string();
  }
  // What this lab can load: its own scenes, and every other lab's by name
  // (names are unique across labs). A lab without scenes of its own (11, 12
  // run lab 06's and lab 04's) lists all of them, grouped by lab.
  auto joined = [](const std::vector<std::string>& names) {
    std::string text;
    for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
    return text;
  };
  const std::vector<std::string> own = list_scene_names(lab_scene_dir);
  std::string known;
  if (!own.empty()) {
    known = "this lab ships: " + joined(own) + "; any other lab's scene loads by its name too";
  } else {
    known = "this lab ships none; it loads any lab's scene by name:";
    for (std::size_t p = 1; p < places.size(); ++p) {
      const std::vector<std::string> names = list_scene_names(places[p].string());
      if (!names.empty()) known += " " + places[p].parent_path().filename().string() + ": " + joined(names) + ";";
    }
    known.pop_back();
  }
  throw InputError(flag + ": no scene named '" + name_or_path + "' (" + known + ")");
}

std::string Range::text() const {
  // "1e+06" -> "1e6", "1e-09" -> "1e-9": the form a scene or a flag is written in.
  auto shown = [](double value) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%g", value);
    std::string text = buffer;
    const std::size_t e = text.find('e');
    if (e == std::string::npos) return text;
    std::string exponent = text.substr(e + 1);
    const bool negative = exponent[0] == '-';
    exponent = exponent.substr(exponent.find_first_not_of("+-0"));
    return text.substr(0, e + 1) + (negative ? "-" : "") + exponent;
  };
  std::string result = (open_low ? "(" : "[") + shown(low) + ", " + shown(high) + "]";
  if (*unit != '\0') result += std::string(" ") + unit;
  return result;
}

const char* shape_name(ColliderShape shape) {
  switch (shape) {
    case ColliderShape::kPlane: return "plane";
    case ColliderShape::kSphere: return "sphere";
    case ColliderShape::kCapsule: return "capsule";
  }
  return "plane";
}

std::string lab_scene_dir(const std::string& lab) {
  return (fs::path(source_dir()) / "labs" / lab / "scenes").string();
}

std::vector<std::string> list_scene_names(const std::string& scene_dir) {
  std::vector<std::string> names;
  std::error_code error;
  if (!fs::is_directory(scene_dir, error)) return names;
  for (const auto& entry : fs::directory_iterator(scene_dir, error)) {
    if (entry.path().extension() == ".json") names.push_back(entry.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

std::string describe(const Scene& scene) {
  std::ostringstream text;
  text << scene.name << " (" << scene.particles.size() << " particles, " << scene.springs.size() << " springs";
  if (!scene.triangles.empty()) text << ", " << scene.triangles.size() << " triangles";
  text << ")";
  return text.str();
}

int frames_in(double seconds, double dt) {
  if (std::isnan(seconds) || !std::isfinite(dt) || !(dt > 0.0)) {
    throw std::invalid_argument("frames_in: needs a number of seconds and a finite dt > 0 (got seconds " +
                                std::to_string(seconds) + ", dt " + std::to_string(dt) + ")");
  }
  // Rounded as a double and clamped before the cast: a cast out of int's range is undefined.
  const double frames = std::round(seconds / dt);
  if (!(frames >= 1.0)) return 1;
  if (frames >= static_cast<double>(INT_MAX)) return INT_MAX;
  return static_cast<int>(frames);
}

}  // namespace cl
