#pragma once
// Wavefront OBJ text of a particle mesh, for Blender or MeshLab.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"
#include "common/scene.h"

namespace cl {

// One `v` line per particle (17 significant digits), then one `f` line per
// triangle, or, for a scene without triangles, one `l` line per spring.
// OBJ indices start at 1. `comment` becomes the first line, after "# ".
std::string obj_text(const Eigen::Matrix3Xd& x, const std::vector<Triangle>& triangles,
                     const std::vector<Spring>& springs, const std::string& comment);

// A run's frame as OBJ: writes dir/frame_NNNNNN.obj (the frame number, six
// digits zero-padded, more past 999999) with the positions x (m, scene order)
// on the scene's triangles or springs, and the comment
// "<lab> scene <name> frame <frame> time <time>" (time in s, 17 digits).
// Atomic; throws InputError when the file cannot be written.
void write_frame_obj(const std::string& dir, const std::string& lab, const Scene& scene, const Eigen::Matrix3Xd& x,
                     int frame, double time);

}  // namespace cl
