// libFuzzer target for the live mode's message parser (common/live_protocol.h,
// docs/DESIGN.md §3, "The live mode"): any bytes are either a command whose
// values are in their ranges and finite, or refused in one line starting
// "live: " in valid UTF-8 (the page's reply is JSON built from it). A crash,
// a sanitizer report or a broken promise is a bug; ./course fuzz copies the
// input into tests/common/live_regressions/, which the unit tests replay.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <nlohmann/json.hpp>

#include "common/live_protocol.h"

namespace {

const char* broken_promise(const std::string& text, const cl::LiveParse& parse, const cl::Knobs& knobs, int particles) {
  if (!parse.ok()) {
    if (parse.error.rfind("live: ", 0) != 0) return "a refusal that does not start with 'live: '";
    if (parse.error.find('\n') != std::string::npos) return "a refusal of more than one line";
    try {
      (void)nlohmann::json(parse.error).dump();
    } catch (const nlohmann::json::exception&) {
      return "a refusal that is not UTF-8 (its JSON reply cannot be built)";
    }
    return nullptr;
  }
  const cl::LiveCommand& command = parse.command;
  if (text.size() > cl::kLiveMessageCap) return "a message over the cap accepted";
  if (!std::isfinite(command.value) || !command.target.allFinite()) return "a non-finite number accepted";
  switch (command.kind) {
    case cl::LiveCommandKind::kSet: {
      if (command.knob < 0 || command.knob >= static_cast<int>(knobs.all().size())) return "an unknown knob accepted";
      const cl::Knob& knob = knobs.all()[static_cast<std::size_t>(command.knob)];
      if (command.value < knob.low || command.value > knob.high) return "a knob value out of range accepted";
      if (knob.integer && std::floor(command.value) != command.value) return "a fraction for an integer knob";
      break;
    }
    case cl::LiveCommandKind::kSpeed:
      if (command.value < cl::kLiveSpeedMin || command.value > cl::kLiveSpeedMax) return "a speed out of range";
      break;
    case cl::LiveCommandKind::kDrag:
      if (command.target.cwiseAbs().maxCoeff() > cl::kLiveReach) return "a drag target out of reach";
      [[fallthrough]];
    case cl::LiveCommandKind::kRelease:
    case cl::LiveCommandKind::kPin:
      if (command.particle < 0 || command.particle >= particles) return "a particle index out of range accepted";
      break;
    default:
      break;
  }
  return nullptr;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const cl::Knobs knobs{{"K", "sweeps", 0, 200, 10, true}, {"dt", "s", 1e-4, 0.05, 1.0 / 60.0, false}};
  const std::string text(reinterpret_cast<const char*>(data), size);
  const int particles = 256;
  const cl::LiveParse parse = cl::parse_live_message(text, knobs, particles);
  if (const char* broken = broken_promise(text, parse, knobs, particles)) {
    std::fprintf(stderr, "the live parser broke a promise: %s (%s)\n", broken, parse.error.c_str());
    std::abort();  // libFuzzer reports the input as a crash
  }
  return 0;
}
