#include "common/obj.h"

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

}  // namespace cl
