#pragma once
// Means of a per-frame measure over consecutive windows of frames, and whether
// the run has settled: the frame loops of labs 04 and 08 run "until steady"
// this way (lab 04: the max strain, lab 08: the chain's total stretch).
#include <deque>

namespace cl {

// Frames are added one at a time; frames 1…W make the first window, W+1…2W the
// second, and so on (W = window_frames). The value may have any unit; the means
// have the same one. The run has settled at a window when the means of the last
// three windows agree to a relative tolerance:
//     spread = max − min of the three,   settled when spread <= tolerance · |last|,
// last being the newest of the three. A measure that is exactly 0 over three
// windows has settled (spread 0 <= 0); any spread around a zero last mean has not.
class WindowMeans {
 public:
  // Throws std::invalid_argument for window_frames < 1.
  explicit WindowMeans(int window_frames);

  // Adds one frame's value; true when it completes a window (its mean is then last()).
  bool add(double value);

  int window_frames() const { return window_frames_; }
  int windows_done() const { return windows_done_; }
  // The newest complete window's mean (0 before the first window completes).
  double last() const { return means_.empty() ? 0.0 : means_.back(); }
  // spread / |last| over the last three windows; -1 before three are complete.
  // When last is 0: 0 if the three are equal, 1 otherwise.
  double relative_spread() const;
  // Three windows are complete and spread <= tolerance · |last|. Never for
  // tolerance <= 0 (or NaN): 0 means "do not stop early".
  bool settled(double tolerance) const;

 private:
  double spread() const;

  int window_frames_;
  int frames_in_window_ = 0;
  double sum_ = 0.0;
  int windows_done_ = 0;
  std::deque<double> means_;  // the last three windows' means, oldest first
};

}  // namespace cl
