// The live mode's protocol (common/live_protocol.h): every refusal is one line starting "live: " and
// leaves the command empty; every accepted message carries its values.
#include "tests/support/catch.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "common/live.h"
#include "common/live_protocol.h"

namespace {

const cl::Knobs& lab04_knobs() {
  static const cl::Knobs knobs{{"K", "sweeps", 0, 200, 10, true}, {"dt", "s", 1e-4, 0.05, 1.0 / 60.0, false}};
  return knobs;
}

// The refusal of `text` on a 256-particle scene; it must name `expected`.
void require_refused(const std::string& text, const std::string& expected) {
  const cl::LiveParse parse = cl::parse_live_message(text, lab04_knobs(), 256);
  CAPTURE(text, parse.error);
  REQUIRE_FALSE(parse.ok());
  CHECK(parse.error.rfind("live: ", 0) == 0);
  CHECK(parse.error.find('\n') == std::string::npos);
  CHECK(parse.error.find(expected) != std::string::npos);
  CHECK_NOTHROW(nlohmann::json(parse.error).dump());  // valid UTF-8: the reply to the page is built from it
}

cl::LiveCommand accepted(const std::string& text) {
  const cl::LiveParse parse = cl::parse_live_message(text, lab04_knobs(), 256);
  CAPTURE(text, parse.error);
  REQUIRE(parse.ok());
  return parse.command;
}

}  // namespace

TEST_CASE("live protocol accepts every command with its values", "[live]") {
  CHECK(accepted(R"({"cmd": "pause"})").kind == cl::LiveCommandKind::kPause);
  CHECK(accepted(R"({"cmd": "resume"})").kind == cl::LiveCommandKind::kResume);
  CHECK(accepted(R"({"cmd": "step"})").kind == cl::LiveCommandKind::kStep);
  CHECK(accepted(R"({"cmd": "reset"})").kind == cl::LiveCommandKind::kReset);
  CHECK(accepted(R"({"cmd": "stop"})").kind == cl::LiveCommandKind::kStop);
  CHECK(accepted(R"({"cmd": "ack"})").kind == cl::LiveCommandKind::kAck);
  const cl::LiveCommand speed = accepted(R"({"cmd": "speed", "value": 0.25})");
  CHECK(speed.kind == cl::LiveCommandKind::kSpeed);
  CHECK(speed.value == 0.25);
  const cl::LiveCommand set = accepted(R"({"value": 32, "cmd": "set", "knob": "K"})");
  CHECK(set.kind == cl::LiveCommandKind::kSet);
  CHECK(set.knob == 0);
  CHECK(set.value == 32.0);
  CHECK(accepted(R"({"cmd": "set", "knob": "dt", "value": 1e-4})").knob == 1);
  CHECK(accepted(R"({"cmd": "set", "knob": "K", "value": 200})").value == 200.0);  // the range's ends are in it
  const cl::LiveCommand drag = accepted(R"({"cmd": "drag", "particle": 255, "x": [0.5, -1, 2e-3]})");
  CHECK(drag.kind == cl::LiveCommandKind::kDrag);
  CHECK(drag.particle == 255);
  CHECK(drag.target == Eigen::Vector3d(0.5, -1.0, 2e-3));
  CHECK(accepted(R"({"cmd": "release", "particle": 0})").particle == 0);
  CHECK(accepted(R"({"cmd": "pin", "particle": 17})").kind == cl::LiveCommandKind::kPin);
}

TEST_CASE("live protocol refuses malformed JSON, a non-object and an unknown command", "[live]") {
  require_refused(R"({"cmd": "pause")", "malformed JSON");
  require_refused("", "malformed JSON");
  require_refused(R"({"cmd": "pause"} trailing)", "malformed JSON");
  require_refused(R"(["pause"])", "a JSON object");
  require_refused(R"({"command": "pause"})", "no \"cmd\"");
  require_refused(R"({"cmd": 3})", "no \"cmd\"");
  require_refused(R"({"cmd": "explode"})", "unknown command 'explode'");
  require_refused(R"({"cmd": "pause", "now": true})", "unknown key 'now'");
  require_refused(R"({"cmd": "drag", "particle": 3})", "missing \"x\"");
  require_refused(R"({"cmd": "line\nbreak"})", "unknown command 'line?break'");  // still one line
  require_refused(R"({"cmd": "pause", "a\u0000b": 1})", "unknown key 'a?b'");
}

// A quoted name is cut at 40 bytes; a cut inside a UTF-8 character made the
// reply's JSON throw, and the program ended (exit 1) on one message.
TEST_CASE("live protocol cuts a quoted name where a character starts", "[live]") {
  const std::string a39(39, 'a');
  require_refused(R"({"cmd": ")" + a39 + R"(\u00e9"})", "unknown command '" + a39 + "'");
  require_refused(R"({"cmd": ")" + a39 + "é\"}", "unknown command '" + a39 + "'");
  require_refused(R"({"cmd": "pause", ")" + a39 + "é\": 1}", "unknown key '" + a39 + "'");
  require_refused(R"({"cmd": "set", "knob": ")" + a39 + R"(é", "value": 1})", "unknown knob '" + a39 + "'");
  require_refused(R"({"cmd": ")" + std::string(38, 'a') + "€\"}", "unknown command '" + std::string(38, 'a') + "'");
  require_refused(R"({"cmd": ")" + std::string(37, 'a') + "😀\"}", "unknown command '" + std::string(37, 'a') + "'");
  require_refused(R"({"cmd": ")" + std::string(36, 'a') + "😀\"}", "unknown command '" + std::string(36, 'a') + "😀'");
  CHECK(cl::live_cut_utf8("é", 1).empty());
  CHECK(cl::live_cut_utf8("aé", 2) == "a");
  CHECK(cl::live_cut_utf8("aé", 3) == "aé");
  CHECK(cl::live_cut_utf8("abc", 40) == "abc");
  const std::string bad = "\xff\xfe";  // not UTF-8 at all: what a reply is built from never throws
  CHECK(nlohmann::json::parse(cl::live_json_text(nlohmann::json{{"text", bad}}))["text"] == "\xef\xbf\xbd\xef\xbf\xbd");
}

// A quoted name is shown in a terminal (stderr) and on the page's error line:
// a C1 control (U+009B is a terminal's CSI), a bidi control (it reorders the
// rest of the line) or a line separator stays out of it, as a C0 control does.
TEST_CASE("live protocol quotes C1, bidi and separator characters as '?'", "[live]") {
  for (const char* hidden : {"\\u0080", "\\u0085", "\\u009b", "\\u009f", "\\u202a", "\\u202b", "\\u202c", "\\u202d",
                             "\\u202e", "\\u2066", "\\u2067", "\\u2068", "\\u2069", "\\u2028", "\\u2029", "\\u0007"}) {
    CAPTURE(hidden);
    require_refused(std::string(R"({"cmd": "a)") + hidden + R"(b"})", "unknown command 'a?b'");
    require_refused(std::string(R"({"cmd": "pause", "k)") + hidden + R"(": 1})", "unknown key 'k?'");
    require_refused(std::string(R"({"cmd": "set", "knob": ")") + hidden + hidden + R"(", "value": 1})", "unknown knob '?\?'");
  }
  // Their neighbours are shown as they are: U+00A0, U+2027, U+202F, U+2065, U+206A, and 'é'.
  require_refused(R"({"cmd": "a\u00a0\u2027\u202f\u2065\u206a\u00e9"})",
                  "unknown command 'a\u00a0\u2027\u202f\u2065\u206a\u00e9'");
}

TEST_CASE("live protocol refuses a key given twice and reads -0 as 0", "[live]") {
  require_refused(R"({"cmd": "pause", "cmd": "stop"})", "a key given twice");
  require_refused(R"({"cmd": "set", "knob": "K", "value": 3, "value": 4})", "a key given twice");
  const cl::LiveCommand zero = accepted(R"({"cmd": "set", "knob": "K", "value": -0.0})");
  CHECK(zero.value == 0.0);
  CHECK_FALSE(std::signbit(zero.value));
}

TEST_CASE("live protocol refuses a knob out of its range, unknown or fractional for an integer knob", "[live]") {
  require_refused(R"({"cmd": "set", "knob": "K", "value": 201})", "K: 201 is not in [0, 200]");
  require_refused(R"({"cmd": "set", "knob": "K", "value": -1})", "is not in [0, 200]");
  require_refused(R"({"cmd": "set", "knob": "K", "value": 2.5})", "K: 2.5 is not an integer");
  require_refused(R"({"cmd": "set", "knob": "dt", "value": 0.5})", "dt: 0.5 is not in [0.0001, 0.05] s");
  require_refused(R"({"cmd": "set", "knob": "omega", "value": 1})", "unknown knob 'omega'");
  require_refused(R"({"cmd": "set", "knob": "K", "value": "8"})", "value: not a number");
  require_refused(R"({"cmd": "speed", "value": 100})", "not in [0.01, 16]");
  require_refused(R"({"cmd": "speed", "value": 0})", "not in [0.01, 16]");
}

TEST_CASE("live protocol refuses a particle index out of range or not an integer", "[live]") {
  require_refused(R"({"cmd": "pin", "particle": 256})", "particle: 256 is not in [0, 255]");
  require_refused(R"({"cmd": "pin", "particle": -1})", "particle: -1 is not in [0, 255]");
  require_refused(R"({"cmd": "release", "particle": 18446744073709551615})", "is not in [0, 255]");
  require_refused(R"({"cmd": "pin", "particle": 1.0})", "particle: not an integer");
  require_refused(R"({"cmd": "drag", "particle": "0", "x": [0, 0, 0]})", "particle: not an integer");
  const cl::LiveParse none = cl::parse_live_message(R"({"cmd": "pin", "particle": 0})", lab04_knobs(), 0);
  CHECK_FALSE(none.ok());  // a scene with no particles has no index to give
}

TEST_CASE("live protocol refuses a non-finite number and a drag target out of reach", "[live]") {
  // JSON has no NaN or inf literal, and nlohmann/json refuses a number too
  // large for a double as a parse error: no message can carry a non-finite one.
  require_refused(R"({"cmd": "drag", "particle": 0, "x": [0, 1e400, 0]})", "malformed JSON");
  require_refused(R"({"cmd": "set", "knob": "dt", "value": -1e999})", "malformed JSON");
  require_refused(R"({"cmd": "drag", "particle": 0, "x": [0, Infinity, 0]})", "malformed JSON");
  require_refused(R"({"cmd": "drag", "particle": 0, "x": [0, NaN, 0]})", "malformed JSON");
  require_refused(R"({"cmd": "drag", "particle": 0, "x": [0, 0]})", "x: not 3 numbers");
  require_refused(R"({"cmd": "drag", "particle": 0, "x": [0, 0, null]})", "x: not a number");
  require_refused(R"({"cmd": "drag", "particle": 0, "x": [0, 0, 2e4]})", "beyond 10000 m");
}

TEST_CASE("live protocol refuses a message over the size cap", "[live]") {
  const std::string padded = R"({"cmd": "pause", "pad": ")" + std::string(cl::kLiveMessageCap, 'x') + "\"}";
  require_refused(padded, "over the cap of 4096");
  const std::string spaced = R"({"cmd": "pause")" + std::string(cl::kLiveMessageCap - 16, ' ') + "}";
  REQUIRE(spaced.size() == cl::kLiveMessageCap);
  CHECK(accepted(spaced).kind == cl::LiveCommandKind::kPause);  // exactly the cap is still a message
}

TEST_CASE("live knob declarations refuse a bad range and a repeated name and widen a range to the starting value", "[live]") {
  CHECK_THROWS_AS((cl::Knobs{{"K", "", 0, 10, std::numeric_limits<double>::quiet_NaN(), false}}),
                  std::invalid_argument);
  const cl::Knobs widened{{"K", "", 0, 10, 11, true}, {"dt", "s", 1e-4, 0.05, 1e-5, false}};
  CHECK(widened.all()[0].high == 11.0);  // a flag's value past the range widens it
  CHECK(widened.all()[1].low == 1e-5);
  CHECK_THROWS_AS((cl::Knobs{{"K", "", 10, 0, 5, true}}), std::invalid_argument);
  CHECK_THROWS_AS((cl::Knobs{{"K", "", 0, 10, 2.5, true}}), std::invalid_argument);
  CHECK_THROWS_AS((cl::Knobs{{"dt", "s", 0, std::numeric_limits<double>::infinity(), 1, false}}), std::invalid_argument);
  CHECK_THROWS_AS((cl::Knobs{{"", "", 0, 1, 0, false}}), std::invalid_argument);
  CHECK_THROWS_AS((cl::Knobs{{"K", "", 0, 1, 0, true}, {"K", "", 0, 1, 0, true}}), std::invalid_argument);
  const cl::Knobs& knobs = lab04_knobs();
  CHECK(knobs.integer(0) == 10);
  CHECK(knobs[1] == 1.0 / 60.0);
  CHECK(knobs.find("dt") == 1);
  CHECK(knobs.find("k") == -1);
  CHECK(knobs.json().find(R"("name":"K")") != std::string::npos);
  CHECK(knobs.json().find(R"("integer":true)") != std::string::npos);
}

// Inputs the fuzzer (fuzz/fuzz_live.cpp) found to break the parser, kept in
// tests/common/live_regressions/: each must now parse or be refused in one line.
TEST_CASE("live protocol replays the fuzzer's saved inputs", "[live]") {
  const std::filesystem::path folder = std::filesystem::path(CL_SOURCE_DIR) / "tests/common/live_regressions";
  int replayed = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().filename() == "README.md") continue;
    std::ifstream in(entry.path(), std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    const cl::LiveParse parse = cl::parse_live_message(text.str(), lab04_knobs(), 256);
    CAPTURE(entry.path().string(), parse.error);
    CHECK((parse.ok() || (parse.error.rfind("live: ", 0) == 0 && parse.error.find('\n') == std::string::npos)));
    CHECK_NOTHROW(nlohmann::json(parse.error).dump());
    ++replayed;
  }
  CHECK(replayed >= 1);  // the folder holds at least its seed
}

TEST_CASE("a live lab rebuilds only when what its solver was built for changed", "[common][live]") {
  cl::BuiltFor built;
  Eigen::VectorXd inv_mass = Eigen::VectorXd::Ones(3);
  CHECK(built.update(inv_mass, {0.01, 1e3}));        // the first build
  CHECK_FALSE(built.update(inv_mass, {0.01, 1e3}));  // K turned: dt and k as built
  CHECK(built.update(inv_mass, {0.02, 1e3}));        // dt
  CHECK(built.update(inv_mass, {0.02, 1e4}));        // k
  inv_mass[1] = 0.0;                                 // a pin or a held particle
  CHECK(built.update(inv_mass, {0.02, 1e4}));
  CHECK_FALSE(built.update(inv_mass, {0.02, 1e4}));
  CHECK(built.update(Eigen::VectorXd::Ones(4), {0.02, 1e4}));  // another size: never compared entrywise
}
