#pragma once
// Scenes: the JSON format of docs/DESIGN.md §3, with strict validation.
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"
#include "common/particles.h"

namespace cl {

// Bad input: the message is one line naming the file, the field and the index,
// e.g. "scenes/bad.json: particles[3].mass: must be > 0 (got -1)".
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A closed or half-open interval of doubles with its unit, for messages:
// "[1e-12, 1e12] kg", "(0, 1e6] m".
struct Range {
  double low;
  double high;
  bool open_low;     // (low, high]: low itself is refused (a radius of 0)
  const char* unit;  // "" for a pure number
  constexpr bool contains(double value) const {
    return (open_low ? value > low : value >= low) && value <= high;
  }
  std::string text() const;
};

// The ranges of every number a scene (and the common flags --dt, --steps)
// may give: one rule, in this one place, that the loader (scene.cpp), the
// flags (cli.cpp), the promises the fuzzer checks
// (tests/support/scene_promises.h) and docs/DESIGN.md §3 all follow. Each is
// wide beyond any physical scene (a coordinate of 1000 km, a mass from a
// nanogram to a billion tonnes) and narrow enough that a step's
// arithmetic stays finite with over 250 orders of magnitude to spare: the
// largest product a solver forms is about k Δt² / m ≤ 1e15 · 10² / 1e-18 =
// 1e35 (a cloth's mass is shared by up to 1024² particles), and a length's
// fourth power at most (2√3 · 1e6)⁴ ≈ 2e26.
namespace limits {
inline constexpr Range kCoordinate{-1e6, 1e6, false, "m"};  // a position's, a collider point's, per axis
inline constexpr Range kLength{0.0, 1e6, true, "m"};        // radius, cloth width/height, chain link
inline constexpr Range kRest{0.0, 1e6, false, "m"};         // a spring's rest length, the jitter amplitude
inline constexpr Range kVelocity{-1e8, 1e8, false, "m/s"};  // per axis: a third of light's speed
inline constexpr Range kGravity{-1e6, 1e6, false, "m/s²"};  // per axis: 1e5 g
inline constexpr Range kMass{1e-12, 1e12, false, "kg"};     // a particle's, a chain's per particle, a cloth's total
inline constexpr Range kStiffness{1e-6, 1e15, false, "N/m"};  // or "inf": 1/k and k/m stay finite
inline constexpr Range kDt{1e-9, 10.0, false, "s"};          // 1/Δt² ≤ 1e18, g Δt² ≤ 2e8 m
inline constexpr Range kFriction{0.0, 1e9, false, ""};       // Coulomb's μ; 1e3 already never slides
inline constexpr int kMaxSteps = 100'000'000;
// The generators' size caps: a cloth of 1024 × 1024 particles (about 200 MB
// with its springs and triangles), a chain of as many. Larger is a typo, not a
// scene: 4096² would take 3.5 GB before the first step.
inline constexpr int kMaxClothSide = 1024;
inline constexpr int kMaxChainLinks = kMaxClothSide * kMaxClothSide;
}  // namespace limits

// A static collider the cloth may touch (lab 14; docs/DESIGN.md §3). Points
// in limits::kCoordinate; `normal` has length 1; radius in limits::kLength;
// friction (Coulomb's μ) in limits::kFriction.
enum class ColliderShape { kPlane, kSphere, kCapsule };
struct Collider {
  ColliderShape shape = ColliderShape::kPlane;
  Eigen::Vector3d a = Eigen::Vector3d::Zero();  // plane: a point on it; sphere: the centre; capsule: one end (m)
  Eigen::Vector3d b = Eigen::Vector3d::Zero();  // capsule: the other end (m; may equal a); unused otherwise
  Eigen::Vector3d normal{0.0, 1.0, 0.0};        // plane: the unit normal, pointing to the free side
  double radius = 0.0;                          // sphere, capsule: m, > 0
  double friction = 0.0;                        // Coulomb's μ, >= 0
};

// "plane", "sphere" or "capsule".
const char* shape_name(ColliderShape shape);

struct Scene {
  std::string name;
  std::string source;                       // file the scene came from
  Eigen::Vector3d gravity{0.0, -9.81, 0.0};  // m/s²
  double dt = 1.0 / 60.0;                   // s
  int steps = 120;
  Particles particles;
  std::vector<Spring> springs;       // empty unless the scene declares springs
  std::vector<Triangle> triangles;   // empty unless the scene declares triangles
  std::vector<Collider> colliders;   // empty unless the scene declares colliders (lab 14 models them)
  // Generator layout for drawing: a cloth's grid size (0 x 0 otherwise).
  int grid_nx = 0;
  int grid_ny = 0;
};

// Parses scene text; `source` names the file in error messages. Throws InputError.
Scene parse_scene(const std::string& text, const std::string& source);

// Reads and parses a scene file. Throws InputError.
Scene load_scene(const std::string& path);

// Resolves --scene: an argument that names an existing file or ends in .json is
// a path; otherwise it is a scene name looked up as NAME.json in lab_scene_dir,
// then in every lab's scenes/. Throws InputError for an unknown name, blaming
// `flag` (the option that gave it) and listing what the lab can load: its own
// scenes, or, for a lab without any (labs 11 and 12), every lab's by lab.
std::string resolve_scene_path(const std::string& name_or_path, const std::string& lab_scene_dir,
                               const std::string& flag = "--scene");

// Every scene name shipped in a scenes directory, sorted.
std::vector<std::string> list_scene_names(const std::string& scene_dir);

// labs/LAB/scenes in this course tree, as an absolute path. Drivers and tests
// see it as CL_LAB_SCENE_DIR (cmake/AddLab.cmake); a function rather than a
// path on every compile line, so that the tree's path is compiled into one
// file (common/source_dir.cpp) and a lab's compile lines do not depend on
// where it lies.
std::string lab_scene_dir(const std::string& lab);

// One line for a driver's header: "name (N particles, M springs)", with
// ", K triangles" before the ")" when the scene has triangles. A scene without
// springs says "0 springs"; an empty name leaves the text to start with " (".
std::string describe(const Scene& scene);

// The steps of dt (s) that make up `seconds` (s), rounded to the nearest and at
// least 1: a window or a mark of `seconds` in a run of frames. Half a step
// rounds away from zero; seconds <= dt/2 (0 and negative included) gives 1, and
// a count past INT_MAX gives INT_MAX. Throws std::invalid_argument for a NaN
// `seconds` or a dt that is not a finite number > 0.
int frames_in(double seconds, double dt);

}  // namespace cl
