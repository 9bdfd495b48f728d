#pragma once
// Constraint data as plain records. Solvers read these; they never own state.
#include <limits>

namespace cl {

constexpr double kInfiniteStiffness = std::numeric_limits<double>::infinity();

// A distance constraint ‖x_i − x_j‖ = rest_length, or a spring of that rest
// length when stiffness (N/m) is finite. Infinite stiffness means a hard constraint.
struct Spring {
  int i = 0;
  int j = 0;
  double rest_length = 0.0;                 // m, >= 0
  double stiffness = kInfiniteStiffness;    // N/m, > 0
};

// A triangle; its rest shape is the shape it had when the scene was loaded.
struct Triangle {
  int i = 0;
  int j = 0;
  int k = 0;
  double rest_area = 0.0;  // m², > 0
};

}  // namespace cl
