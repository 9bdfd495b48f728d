#include "common/live_protocol.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace cl {

namespace {

std::string live_number_text(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

// The fields each command takes besides "cmd".
const std::vector<std::pair<const char*, std::vector<const char*>>>& live_command_fields() {
  static const std::vector<std::pair<const char*, std::vector<const char*>>> fields{
      {"pause", {}},        {"resume", {}},          {"step", {}},
      {"reset", {}},        {"stop", {}},            {"ack", {}},
      {"speed", {"value"}}, {"set", {"knob", "value"}}, {"drag", {"particle", "x"}},
      {"release", {"particle"}}, {"pin", {"particle"}}};
  return fields;
}

// Whether the UTF-8 bytes at text[at] start a character an error line must
// not show as itself; its length in bytes, 0 when it may be shown. C0 and DEL
// (a "\n" in a JSON string breaks the line), C1 (U+0080-U+009F: U+009B is a
// terminal's CSI), the bidi controls (U+202A-U+202E, U+2066-U+2069: they
// reorder the rest of the line as a terminal or the page shows it) and the
// line and paragraph separators U+2028, U+2029.
std::size_t hidden_character(const std::string& text, std::size_t at) {
  const auto byte = [&text](std::size_t i) { return i < text.size() ? static_cast<unsigned char>(text[i]) : 0u; };
  const unsigned first = byte(at);
  if (first < 0x20 || first == 0x7f) return 1;
  if (first == 0xc2 && byte(at + 1) >= 0x80 && byte(at + 1) <= 0x9f) return 2;
  if (first == 0xe2 && byte(at + 1) == 0x80 && byte(at + 2) >= 0xa8 && byte(at + 2) <= 0xae) return 3;
  if (first == 0xe2 && byte(at + 1) == 0x81 && byte(at + 2) >= 0xa6 && byte(at + 2) <= 0xa9) return 3;
  return 0;
}

// A name from the message, as an error line may quote it: at most 40 bytes,
// cut where a character starts (a cut inside a UTF-8 character made the
// reply's JSON invalid), each character hidden_character names as one '?',
// so the line stays one line and reads in its own order.
std::string quoted(const std::string& text) {
  const std::string cut = live_cut_utf8(text, 40);
  std::string shown;
  for (std::size_t at = 0; at < cut.size();) {
    const std::size_t hidden = hidden_character(cut, at);
    shown += hidden > 0 ? std::string("?") : cut.substr(at, 1);
    at += hidden > 0 ? hidden : 1;
  }
  return "'" + shown + "'";
}

// A finite number from `value`, or the reason it is not one.
std::string read_finite(const nlohmann::json& value, const char* key, double& out) {
  if (!value.is_number()) return std::string(key) + ": not a number";
  out = value.get<double>();
  if (!std::isfinite(out)) return std::string(key) + ": not a finite number";
  return {};
}

std::string read_particle(const nlohmann::json& value, long long particles, int& out) {
  if (!value.is_number_integer()) return "particle: not an integer";
  const long long index = value.is_number_unsigned() && value.get<unsigned long long>() > 1ull << 62
                              ? -1
                              : value.get<long long>();
  if (index < 0 || index >= particles) {
    return "particle: " + value.dump() + " is not in [0, " + std::to_string(particles - 1) + "]";
  }
  out = static_cast<int>(index);
  return {};
}

}  // namespace

std::string live_cut_utf8(const std::string& text, std::size_t bytes) {
  if (text.size() <= bytes) return text;
  std::size_t cut = bytes;
  while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0u) == 0x80u) --cut;  // a continuation byte
  return text.substr(0, cut);
}

std::string live_json_text(const nlohmann::json& value) {
  return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

Knobs::Knobs(std::initializer_list<Knob> knobs) : Knobs(std::vector<Knob>(knobs)) {}

Knobs::Knobs(std::vector<Knob> knobs) : knobs_(std::move(knobs)) {
  std::set<std::string> names;
  for (Knob& knob : knobs_) {
    if (std::isfinite(knob.value) && knob.low <= knob.high) {
      knob.low = std::min(knob.low, knob.value);
      knob.high = std::max(knob.high, knob.value);
    }
    const bool range_ok = std::isfinite(knob.low) && std::isfinite(knob.high) && knob.low <= knob.high;
    const bool whole = !knob.integer || (std::floor(knob.low) == knob.low && std::floor(knob.high) == knob.high &&
                                         std::floor(knob.value) == knob.value);
    if (knob.name.empty() || !names.insert(knob.name).second || !range_ok || !whole ||
        !(knob.value >= knob.low && knob.value <= knob.high)) {
      throw std::invalid_argument("Knobs: knob '" + knob.name + "' needs a unique name, a finite range low <= high " +
                                  "and a value in it (whole numbers for an integer knob); got [" +
                                  live_number_text(knob.low) + ", " + live_number_text(knob.high) + "] and " +
                                  live_number_text(knob.value));
    }
  }
}

int Knobs::find(const std::string& name) const {
  for (std::size_t k = 0; k < knobs_.size(); ++k) {
    if (knobs_[k].name == name) return static_cast<int>(k);
  }
  return -1;
}

std::string Knobs::json() const {
  nlohmann::json list = nlohmann::json::array();
  for (const Knob& knob : knobs_) {
    list.push_back({{"name", knob.name}, {"unit", knob.unit}, {"low", knob.low}, {"high", knob.high},
                    {"value", knob.value}, {"integer", knob.integer}});
  }
  return live_json_text(list);
}

LiveParse parse_live_message(const std::string& text, const Knobs& knobs, long long particles) {
  LiveParse parse;
  auto refuse = [&parse](const std::string& why) {
    parse.error = "live: " + why;
    return parse;
  };
  if (text.size() > kLiveMessageCap) {
    return refuse("a message of " + std::to_string(text.size()) + " bytes, over the cap of " +
                  std::to_string(kLiveMessageCap));
  }
  // A key given twice is refused: JSON parsers disagree on which one wins ({"cmd":"pause","cmd":"stop"}).
  std::vector<std::set<std::string>> keys;
  bool repeated = false;
  const nlohmann::json::parser_callback_t watch = [&keys, &repeated](int, nlohmann::json::parse_event_t event,
                                                                       nlohmann::json& parsed) {
    if (event == nlohmann::json::parse_event_t::object_start) keys.emplace_back();
    if (event == nlohmann::json::parse_event_t::object_end && !keys.empty()) keys.pop_back();
    if (event == nlohmann::json::parse_event_t::key && !keys.empty() && !keys.back().insert(parsed.get<std::string>()).second) {
      repeated = true;
    }
    return true;
  };
  const nlohmann::json message = nlohmann::json::parse(text, watch, false);
  if (message.is_discarded()) return refuse("malformed JSON");
  if (repeated) return refuse("a key given twice");
  if (!message.is_object()) return refuse("a message is a JSON object with \"cmd\"");
  const auto cmd = message.find("cmd");
  if (cmd == message.end() || !cmd->is_string()) return refuse("no \"cmd\" string");
  const std::string name = cmd->get<std::string>();
  const std::vector<const char*>* fields = nullptr;
  std::size_t kind = 0;
  for (; kind < live_command_fields().size(); ++kind) {
    if (name == live_command_fields()[kind].first) {
      fields = &live_command_fields()[kind].second;
      break;
    }
  }
  if (fields == nullptr) return refuse("unknown command " + quoted(name));
  parse.command.kind = static_cast<LiveCommandKind>(kind);
  for (const auto& item : message.items()) {
    if (item.key() == "cmd") continue;
    bool known = false;
    for (const char* field : *fields) known = known || item.key() == field;
    if (!known) return refuse(name + ": unknown key " + quoted(item.key()));
  }
  for (const char* field : *fields) {
    if (!message.contains(field)) return refuse(name + ": missing \"" + field + "\"");
  }
  LiveCommand& command = parse.command;
  std::string problem;
  switch (command.kind) {
    case LiveCommandKind::kSpeed:
      problem = read_finite(message["value"], "value", command.value);
      if (problem.empty() && !(command.value >= kLiveSpeedMin && command.value <= kLiveSpeedMax)) {
        problem = "value: " + live_number_text(command.value) + " is not in [" + live_number_text(kLiveSpeedMin) + ", " +
                  live_number_text(kLiveSpeedMax) + "]";
      }
      break;
    case LiveCommandKind::kSet: {
      if (!message["knob"].is_string()) return refuse("set: knob: not a string");
      const std::string knob = message["knob"].get<std::string>();
      command.knob = knobs.find(knob);
      if (command.knob < 0) return refuse("set: unknown knob " + quoted(knob));
      const Knob& declared = knobs.all()[static_cast<std::size_t>(command.knob)];
      problem = read_finite(message["value"], "value", command.value);
      if (problem.empty() && !(command.value >= declared.low && command.value <= declared.high)) {
        problem = knob + ": " + live_number_text(command.value) + " is not in [" + live_number_text(declared.low) + ", " +
                  live_number_text(declared.high) + "]" + (declared.unit.empty() ? "" : " " + declared.unit);
      } else if (problem.empty() && declared.integer && std::floor(command.value) != command.value) {
        problem = knob + ": " + live_number_text(command.value) + " is not an integer";
      }
      command.value += 0.0;  // -0 is 0
      break;
    }
    case LiveCommandKind::kDrag: {
      problem = read_particle(message["particle"], particles, command.particle);
      const nlohmann::json& x = message["x"];
      if (problem.empty() && (!x.is_array() || x.size() != 3)) problem = "x: not 3 numbers";
      for (std::size_t a = 0; problem.empty() && a < 3; ++a) {
        problem = read_finite(x[a], "x", command.target[static_cast<Eigen::Index>(a)]);
        if (problem.empty() && std::abs(command.target[static_cast<Eigen::Index>(a)]) > kLiveReach) {
          problem = "x: " + live_number_text(command.target[static_cast<Eigen::Index>(a)]) + " m is beyond " +
                    live_number_text(kLiveReach) + " m";
        }
      }
      break;
    }
    case LiveCommandKind::kRelease:
    case LiveCommandKind::kPin:
      problem = read_particle(message["particle"], particles, command.particle);
      break;
    default:
      break;
  }
  if (!problem.empty()) return refuse(name + ": " + problem);
  return parse;
}

}  // namespace cl
