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

// A static collider the cloth may touch (lab 14; docs/DESIGN.md §3). Every
// number finite; `normal` has length 1; radius > 0; friction (Coulomb's μ) >= 0.
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
// file (scene.cpp) and a lab's compile lines do not depend on where it lies.
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
