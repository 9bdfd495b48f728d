#include "common/obj.h"

#include <cstdio>
#include <sstream>

#include "common/output.h"

namespace cl {

std::string obj_text(const Eigen::Matrix3Xd& x, const std::vector<Triangle>& triangles,
                     const std::vector<Spring>& springs, const std::string& comment) {
  std::ostringstream text;
  text << "# " << comment << '\n';
  for (Eigen::Index p = 0; p < x.cols(); ++p) {
    text << "v " << format_double(x(0, p)) << ' ' << format_double(x(1, p)) << ' ' << format_double(x(2, p))
         << '\n';
  }
  if (!triangles.empty()) {
    for (const Triangle& t : triangles) text << "f " << t.i + 1 << ' ' << t.j + 1 << ' ' << t.k + 1 << '\n';
  } else {
    for (const Spring& s : springs) text << "l " << s.i + 1 << ' ' << s.j + 1 << '\n';
  }
  return text.str();
}

void write_frame_obj(const std::string& dir, const std::string& lab, const Scene& scene, const Eigen::Matrix3Xd& x,
                     int frame, double time) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06d.obj", frame);
  const std::string comment =
      lab + " scene " + scene.name + " frame " + std::to_string(frame) + " time " + format_double(time);
  write_file_atomic(join_path(dir, name), obj_text(x, scene.triangles, scene.springs, comment));
}

}  // namespace cl
