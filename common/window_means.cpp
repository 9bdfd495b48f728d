#include "common/window_means.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace cl {

WindowMeans::WindowMeans(int window_frames) : window_frames_(window_frames) {
  if (window_frames < 1) {
    throw std::invalid_argument("WindowMeans: window_frames must be >= 1 (got " + std::to_string(window_frames) + ")");
  }
}

bool WindowMeans::add(double value) {
  sum_ += value;
  if (++frames_in_window_ < window_frames_) return false;
  means_.push_back(sum_ / window_frames_);
  if (means_.size() > 3) means_.pop_front();
  ++windows_done_;
  frames_in_window_ = 0;
  sum_ = 0.0;
  return true;
}

double WindowMeans::spread() const {
  const auto [low, high] = std::minmax_element(means_.begin(), means_.end());
  return *high - *low;
}

double WindowMeans::relative_spread() const {
  if (means_.size() < 3) return -1.0;
  const double range = spread();
  const double magnitude = std::abs(means_.back());
  return magnitude > 0.0 ? range / magnitude : (range > 0.0 ? 1.0 : 0.0);
}

bool WindowMeans::settled(double tolerance) const {
  return tolerance > 0.0 && means_.size() == 3 && spread() <= tolerance * std::abs(means_.back());
}

}  // namespace cl
