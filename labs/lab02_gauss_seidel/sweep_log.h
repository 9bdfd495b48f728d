#pragma once
// Lab 02 — given code (not graded): the spring orders of a Gauss-Seidel run
// and the per-sweep convergence log that the lab 02 and lab 03 executables
// print, write as CSV and judge (converged, not converged, diverged).
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include <nlohmann/json.hpp>

#include "common/constraints.h"
#include "common/csv.h"

namespace cl::lab02 {

enum class Order {
  kForward,  // 0, 1, …, m−1 every sweep
  kReverse,  // m−1, …, 1, 0 every sweep
  kRandom,   // a fresh shuffle of 0 … m−1 every sweep, reproducible from the seed
};

// "forward", "reverse" or "random"; the CLI checks the spelling.
Order order_from_name(const std::string& name);
const char* order_name(Order order);

// The spring order of each sweep in turn.
class SweepOrder {
 public:
  SweepOrder(std::size_t spring_count, Order order, std::uint64_t seed);
  // The order for the next sweep (valid until the next call).
  const std::vector<int>& next();

 private:
  Order order_;
  std::uint64_t state_;
  std::vector<int> indices_;
};

// What one sweep did, measured outside the timed part.
struct SweepRecord {
  int sweep = 0;                     // 0 = the initial state
  double max_strain_error = 0.0;     // max over springs, see common/metrics.h
  double rms_strain_error = 0.0;
  double max_position_change = 0.0;  // max over particles of ‖x_after − x_before‖, m
  double rms_position_change = 0.0;  // m
  double sweep_seconds = 0.0;        // wall time of this sweep alone, s
  double total_seconds = 0.0;        // wall time of sweeps 1 … this one, s
};

enum class Outcome { kConverged, kNotConverged, kDiverged };
const char* outcome_name(Outcome outcome);

// The records of one run and the judgement of how it went.
//   diverged:      a strain error or a position change is not finite, or the
//                  max strain error has grown past `growth_limit` times its
//                  starting value (or times the tolerance, or 1e-12, whichever
//                  is largest): the sweeps made the state worse, not better.
//                  The run is meant to stop there.
//   converged:     the final max strain error is <= tolerance.
//   not converged: neither (too few sweeps, an infeasible scene, a stall).
class ConvergenceLog {
 public:
  ConvergenceLog(const std::vector<Spring>& springs, double tolerance, double growth_limit = 10.0);

  // Sweep 0: the state before any sweep.
  void start(const Eigen::Matrix3Xd& x);
  // Records one sweep from `before` to `after` that took `seconds`. Returns
  // false when the run diverged at this sweep (see diverged_reason()).
  bool record(const Eigen::Matrix3Xd& before, const Eigen::Matrix3Xd& after, double seconds);

  const std::vector<SweepRecord>& records() const { return records_; }
  const SweepRecord& last() const { return records_.back(); }
  Outcome outcome() const;
  bool diverged() const { return diverged_at_ >= 0; }
  int diverged_at() const { return diverged_at_; }               // -1: did not diverge
  const std::string& diverged_reason() const { return reason_; }  // "strain error is not finite", …
  int sweeps_to_tolerance() const { return sweeps_to_tolerance_; }  // -1: never reached
  double tolerance() const { return tolerance_; }

  // One row per record: sweep, max/rms strain error, max/rms position change,
  // sweep and total seconds.
  CsvTable table() const;

 private:
  std::vector<Spring> springs_;
  double tolerance_;
  double growth_limit_;
  double blow_up_ = 0.0;  // the max strain error that counts as diverged
  std::vector<SweepRecord> records_;
  int diverged_at_ = -1;
  int sweeps_to_tolerance_ = -1;
  std::string reason_;
};

// Sweeps worth printing: 0, 1, 2, 5, 10, 20, 50, … and the last one.
bool worth_printing(int sweep, int last_sweep);

// The log as text for a terminal: a table of the sweeps worth printing, then
// one line with the outcome ("diverged at sweep 12: strain error is not finite").
std::string format_log(const ConvergenceLog& log);
std::string format_outcome(const ConvergenceLog& log);

// Summary fields: outcome, diverged, diverged_at_sweep, tolerance,
// sweeps_to_tolerance (null when not reached), sweeps, positions_after_sweep
// (the sweep whose state the summary's positions are: the last finite one).
nlohmann::ordered_json outcome_json(const ConvergenceLog& log);

// max over particles of ‖a_p − b_p‖ (m); infinity when either is not finite.
double max_distance(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b);

}  // namespace cl::lab02
