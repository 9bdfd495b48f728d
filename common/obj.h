#pragma once
// Wavefront OBJ text of a particle mesh, for Blender or MeshLab.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"

namespace cl {

// One `v` line per particle (17 significant digits), then one `f` line per
// triangle, or, for a scene without triangles, one `l` line per spring.
// OBJ indices start at 1. `comment` becomes the first line, after "# ".
std::string obj_text(const Eigen::Matrix3Xd& x, const std::vector<Triangle>& triangles,
                     const std::vector<Spring>& springs, const std::string& comment);

}  // namespace cl
