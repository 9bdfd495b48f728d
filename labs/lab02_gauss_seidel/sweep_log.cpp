// Lab 02 — given code: sweep orders and the convergence log (see sweep_log.h).
#include "sweep_log.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "common/metrics.h"

namespace cl::lab02 {

namespace {
// splitmix64: the same shuffle on every platform (std::shuffle is not).
std::uint64_t next_bits(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

// Changes of each particle, measured as one max and one root mean square.
void position_change(const Eigen::Matrix3Xd& before, const Eigen::Matrix3Xd& after, double& max, double& rms) {
  max = 0.0;
  double sum_of_squares = 0.0;
  for (Eigen::Index p = 0; p < after.cols(); ++p) {
    const double change = (after.col(p) - before.col(p)).norm();
    if (!(change <= max)) max = change;  // keeps a NaN visible
    sum_of_squares += change * change;
  }
  rms = after.cols() > 0 ? std::sqrt(sum_of_squares / static_cast<double>(after.cols())) : 0.0;
}
}  // namespace

Order order_from_name(const std::string& name) {
  if (name == "forward") return Order::kForward;
  if (name == "reverse") return Order::kReverse;
  if (name == "random") return Order::kRandom;
  throw std::invalid_argument("order must be forward, reverse or random (got " + name + ")");
}

const char* order_name(Order order) {
  switch (order) {
    case Order::kForward: return "forward";
    case Order::kReverse: return "reverse";
    case Order::kRandom: return "random";
  }
  return "?";
}

SweepOrder::SweepOrder(std::size_t spring_count, Order order, std::uint64_t seed)
    : order_(order), state_(seed), indices_(spring_count) {
  for (std::size_t s = 0; s < spring_count; ++s) {
    indices_[s] = static_cast<int>(order == Order::kReverse ? spring_count - 1 - s : s);
  }
}

const std::vector<int>& SweepOrder::next() {
  if (order_ == Order::kRandom) {
    // Fisher-Yates, continuing from the previous sweep's permutation.
    for (std::size_t k = indices_.size(); k > 1; --k) {
      const double unit = static_cast<double>(next_bits(state_) >> 11) * 0x1.0p-53;
      const auto pick = static_cast<std::size_t>(unit * static_cast<double>(k));
      std::swap(indices_[k - 1], indices_[pick < k ? pick : k - 1]);
    }
  }
  return indices_;
}

const char* outcome_name(Outcome outcome) {
  switch (outcome) {
    case Outcome::kConverged: return "converged";
    case Outcome::kNotConverged: return "not converged";
    case Outcome::kDiverged: return "diverged";
  }
  return "?";
}

ConvergenceLog::ConvergenceLog(const std::vector<Spring>& springs, double tolerance, double growth_limit)
    : springs_(springs), tolerance_(tolerance), growth_limit_(growth_limit) {}

void ConvergenceLog::start(const Eigen::Matrix3Xd& x) {
  records_.clear();
  diverged_at_ = -1;
  sweeps_to_tolerance_ = -1;
  reason_.clear();
  const StrainStats strain = strain_stats(x, springs_);
  SweepRecord record;
  record.max_strain_error = strain.max;
  record.rms_strain_error = strain.rms;
  records_.push_back(record);
  if (strain.max <= tolerance_) sweeps_to_tolerance_ = 0;
  // Round-off alone (1e-16 … 1e-13) must never count as growth.
  blow_up_ = growth_limit_ * std::max({std::isfinite(strain.max) ? strain.max : 0.0, tolerance_, 1e-12});
}

bool ConvergenceLog::record(const Eigen::Matrix3Xd& before, const Eigen::Matrix3Xd& after, double seconds) {
  if (records_.empty()) throw std::logic_error("ConvergenceLog::record before start");
  const StrainStats strain = strain_stats(after, springs_);
  SweepRecord record;
  record.sweep = records_.back().sweep + 1;
  record.max_strain_error = strain.max;
  record.rms_strain_error = strain.rms;
  position_change(before, after, record.max_position_change, record.rms_position_change);
  record.sweep_seconds = seconds;
  record.total_seconds = records_.back().total_seconds + seconds;
  records_.push_back(record);

  if (!std::isfinite(strain.max) || !std::isfinite(strain.rms)) {
    reason_ = "strain error is not finite";
  } else if (!std::isfinite(record.max_position_change)) {
    reason_ = "a position change is not finite";
  } else if (strain.max > blow_up_) {
    char text[160];
    std::snprintf(text, sizeof text, "max strain error %.3e has grown past %g times its starting value %.3e",
                  strain.max, growth_limit_, records_.front().max_strain_error);
    reason_ = text;
  }
  if (!reason_.empty()) {
    diverged_at_ = record.sweep;
    return false;
  }
  if (sweeps_to_tolerance_ < 0 && strain.max <= tolerance_) sweeps_to_tolerance_ = record.sweep;
  return true;
}

Outcome ConvergenceLog::outcome() const {
  if (diverged()) return Outcome::kDiverged;
  if (!records_.empty() && records_.back().max_strain_error <= tolerance_) return Outcome::kConverged;
  return Outcome::kNotConverged;
}

CsvTable ConvergenceLog::table() const {
  CsvTable table({"sweep", "max_strain_error", "rms_strain_error", "max_position_change", "rms_position_change",
                  "sweep_seconds", "total_seconds"});
  for (const SweepRecord& record : records_) {
    table.add_row({static_cast<long long>(record.sweep), record.max_strain_error, record.rms_strain_error,
                   record.max_position_change, record.rms_position_change, record.sweep_seconds,
                   record.total_seconds});
  }
  return table;
}

bool worth_printing(int sweep, int last_sweep) {
  if (sweep == last_sweep || sweep <= 2) return true;
  int decade = 1;
  while (decade * 10 <= sweep) decade *= 10;
  return sweep == decade || sweep == 2 * decade || sweep == 5 * decade;
}

std::string format_log(const ConvergenceLog& log) {
  char line[160];
  std::snprintf(line, sizeof line, "  %7s %14s %14s %14s %12s\n", "sweep", "max strain", "rms strain",
                "max |dx| (m)", "time (s)");
  std::string text = line;
  const int last = log.last().sweep;
  for (const SweepRecord& record : log.records()) {
    if (!worth_printing(record.sweep, last)) continue;
    std::snprintf(line, sizeof line, "  %7d %14.6e %14.6e %14.6e %12.3e\n", record.sweep, record.max_strain_error,
                  record.rms_strain_error, record.max_position_change, record.total_seconds);
    text += line;
  }
  return text;
}

std::string format_outcome(const ConvergenceLog& log) {
  char line[240];
  if (log.diverged()) {
    std::snprintf(line, sizeof line, "diverged at sweep %d: %s", log.diverged_at(), log.diverged_reason().c_str());
  } else if (log.sweeps_to_tolerance() >= 0) {
    std::snprintf(line, sizeof line, "converged: max strain error <= %.1e from sweep %d on", log.tolerance(),
                  log.sweeps_to_tolerance());
  } else {
    std::snprintf(line, sizeof line, "not converged: max strain error %.3e > %.1e after %d sweeps",
                  log.last().max_strain_error, log.tolerance(), log.last().sweep);
  }
  return line;
}

nlohmann::ordered_json outcome_json(const ConvergenceLog& log) {
  nlohmann::ordered_json out;
  out["outcome"] = outcome_name(log.outcome());
  out["diverged"] = log.diverged();
  out["diverged_at_sweep"] = log.diverged() ? nlohmann::ordered_json(log.diverged_at()) : nlohmann::ordered_json();
  out["tolerance"] = log.tolerance();
  out["sweeps_to_tolerance"] =
      log.sweeps_to_tolerance() >= 0 ? nlohmann::ordered_json(log.sweeps_to_tolerance()) : nlohmann::ordered_json();
  out["sweeps"] = log.last().sweep;
  // A diverged run reports the last finite state, the one before the sweep that broke.
  out["positions_after_sweep"] = log.diverged() ? log.diverged_at() - 1 : log.last().sweep;
  return out;
}

double max_distance(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
  if (!a.allFinite() || !b.allFinite()) return std::numeric_limits<double>::infinity();
  double max = 0.0;
  for (Eigen::Index p = 0; p < a.cols(); ++p) max = std::max(max, (a.col(p) - b.col(p)).norm());
  return max;
}

}  // namespace cl::lab02
