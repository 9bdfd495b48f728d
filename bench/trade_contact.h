#pragma once
// The speed/accuracy trade with contact (issue 34, experiment 3): lab 14's
// three steps with contact on its drape (a cloth on a sphere above a floor),
// each against the constrained step iterated to convergence, by distance and
// time. trade.cpp runs it for its drape-N scenes; bench/README.md, "Contact
// in the trade", has what it measures and what it found.
#include <string>
#include <vector>

namespace cl::bench {

// The trade's contact scenes are drape-N (N >= 3): lab 14's drape-sphere
// (drape-32 is that scene) with an N x N cloth.
bool is_contact_scene(const std::string& name);

struct ContactTradeOptions {
  std::vector<std::string> scenes;   // drape-N names
  std::vector<std::string> methods;  // contact methods (contact_methods() names); empty: all three
  bool quick = false;                // iteration counts 1, 3, 10, 30 (else 1, 2, 5, ..., 1000)
  int repeats = 5;                   // timed repeats of each step (at least 20 ms of them)
  int warmup = 20;                   // steps before the shared start
  double step_cap = 2.0;             // s: K stops growing once one step takes longer
  std::string out;                   // folder of trade_contact.csv
};

// Throws cl::InputError for a scene that is not drape-N, std::runtime_error in
// a build without lab 14's reference (no contact methods): before any work.
void check_contact_trade(const ContactTradeOptions& options);

// Runs the contact trade, prints a table per scene and writes
// OUT/trade_contact.csv (check_contact_trade first).
void run_contact_trade(const ContactTradeOptions& options);

}  // namespace cl::bench
