#include "common/health.h"

#include <cmath>
#include <cstdio>

namespace cl {

std::string health_problem(const Particles& particles, const StrainStats& strain) {
  if (!all_finite(particles.x)) return "positions are not finite";
  if (!all_finite(particles.v)) return "velocities are not finite";
  if (!std::isfinite(strain.max)) return "strain error is not finite";
  if (strain.max >= kUnstableStrain) {
    char text[96];
    std::snprintf(text, sizeof text, "max strain %.3g >= %.0e: unstable", strain.max, kUnstableStrain);
    return text;
  }
  return {};
}

double energy_scale(const Particles& particles, const Eigen::Vector3d& gravity, double dt) {
  if (particles.size() == 0) return 0.0;
  const Eigen::Vector3d low = particles.x.rowwise().minCoeff();
  const Eigen::Vector3d high = particles.x.rowwise().maxCoeff();
  const double size = (high - low).norm();
  double scale = 0.0, at_rest_scale = 0.0;
  for (Eigen::Index p = 0; p < particles.size(); ++p) {
    const double w = particles.inv_mass[p];
    if (!(w > 0.0)) continue;
    scale += (gravity.norm() * size + 0.5 * particles.v.col(p).squaredNorm()) / w;
    at_rest_scale += 0.5 * (size / dt) * (size / dt) / w;
  }
  return scale > 0.0 ? scale : at_rest_scale;
}

std::string energy_rise_problem(double rise, double scale, const std::string& measured) {
  if (!(scale > 0.0) || !(rise > scale)) return {};
  const char* format = "%s rose %.3g J above its start (more than the scene's %.3g J): unstable";
  std::string text(static_cast<std::size_t>(std::snprintf(nullptr, 0, format, measured.c_str(), rise, scale)), '\0');
  std::snprintf(text.data(), text.size() + 1, format, measured.c_str(), rise, scale);
  return text;
}

}  // namespace cl
