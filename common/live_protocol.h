#pragma once
// The live mode's protocol (docs/DESIGN.md §3, "The live mode"): the knobs a
// lab declares and the page's messages, parsed and validated like a scene
// file. Pure functions, no server: the unit tests and the fuzzer
// (fuzz/fuzz_live.cpp) call them directly.
//
// A message is one JSON object of at most kLiveMessageCap bytes with a "cmd":
//   {"cmd": "pause"} {"cmd": "resume"} {"cmd": "step"} {"cmd": "reset"} {"cmd": "stop"}
//   {"cmd": "ack"}                                the page drew a frame (flow control)
//   {"cmd": "speed", "value": S}                  S in [kLiveSpeedMin, kLiveSpeedMax] × real time
//   {"cmd": "set", "knob": "K", "value": V}       V in the knob's range (an integer for an integer knob)
//   {"cmd": "drag", "particle": i, "x": [x, y, z]}  hold particle i at x (m)
//   {"cmd": "release", "particle": i}             let it go with the drag's velocity
//   {"cmd": "pin", "particle": i}                 pin a free particle, free a pinned one
// Anything else is refused with one line (unknown command or key, a missing
// or mistyped field, a number out of range or not finite, malformed JSON, a
// message over the cap); a refused message changes nothing.
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

namespace cl {

constexpr std::size_t kLiveMessageCap = 4096;  // bytes of one message from the page
constexpr double kLiveSpeedMin = 0.01;         // × real time
constexpr double kLiveSpeedMax = 16.0;
constexpr double kLiveReach = 1e4;             // m: the most |x| a drag target may have, per axis

// One knob of a lab's live run: its name (what "set" names), unit (for the
// page), range [low, high], the value it starts at, and whether it only takes
// integers (an iteration count).
struct Knob {
  std::string name;
  std::string unit;
  double low = 0.0;
  double high = 0.0;
  double value = 0.0;
  bool integer = false;
};

// A lab's knobs, by name or by their order of declaration.
class Knobs {
 public:
  Knobs() = default;
  // A starting value outside [low, high] (a flag's) widens the range to it.
  // Throws std::invalid_argument for an empty or repeated name, a range that
  // is not finite with low <= high, a value that is not finite, or an integer
  // knob with a fractional bound or value.
  Knobs(std::initializer_list<Knob> knobs);
  explicit Knobs(std::vector<Knob> knobs);

  double operator[](std::size_t k) const { return knobs_.at(k).value; }
  int integer(std::size_t k) const { return static_cast<int>(knobs_.at(k).value); }
  // The index of knob `name`; -1 when there is none.
  int find(const std::string& name) const;
  const std::vector<Knob>& all() const { return knobs_; }
  // Sets knob k (the value must have passed parse_live_message's checks).
  void set(std::size_t k, double value) { knobs_.at(k).value = value; }
  // [{"name", "unit", "low", "high", "value", "integer"}, ...] for the page.
  std::string json() const;

 private:
  std::vector<Knob> knobs_;
};

enum class LiveCommandKind { kPause, kResume, kStep, kReset, kStop, kAck, kSpeed, kSet, kDrag, kRelease, kPin };

struct LiveCommand {
  LiveCommandKind kind = LiveCommandKind::kPause;
  int knob = -1;           // kSet: the knob's index
  double value = 0.0;      // kSpeed, kSet
  int particle = -1;       // kDrag, kRelease, kPin: in [0, particles)
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  // kDrag, m
};

// What parse_live_message made of a message: a command, or (error not empty)
// the one line that refuses it, "live: <what is wrong>".
struct LiveParse {
  LiveCommand command;
  std::string error;
  bool ok() const { return error.empty(); }
};

// The first `bytes` bytes of UTF-8 `text`, fewer when that would cut a
// character: the cut backs off to where a character starts.
std::string live_cut_utf8(const std::string& text, std::size_t bytes);

// `value` as JSON text for a client; never throws (a string that is not
// UTF-8 has U+FFFD where its bad bytes were, where dump() would throw).
std::string live_json_text(const nlohmann::json& value);

// Parses and validates one message from the page against `knobs` and a scene
// of `particles` particles. Never throws; never accepts a non-finite number.
LiveParse parse_live_message(const std::string& text, const Knobs& knobs, long long particles);

}  // namespace cl
