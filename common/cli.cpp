#include "common/cli.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <iostream>
#include <sstream>
#include <utility>

#include <CLI/CLI.hpp>

#include "common/not_implemented.h"
#include "common/output.h"
#include "common/trajectory.h"

namespace cl {

namespace {
// The scenes this run loaded, for --check's line (in the order loaded, each once).
std::vector<std::string> loaded_scenes;
// Whether the mode this run is in reads --method (a mode that does not is
// not said to run one in --check's line); refuse_unused_flags decides it.
bool method_read_here = true;

void note_scene(const Scene& scene) {
  std::ostringstream text;
  text << describe(scene);
  if (scene.steps > 0 && scene.dt > 0.0) text << " dt " << scene.dt << " s, " << scene.steps << " steps";
  if (!scene.colliders.empty()) text << ", " << scene.colliders.size() << " colliders";
  if (std::find(loaded_scenes.begin(), loaded_scenes.end(), text.str()) == loaded_scenes.end()) {
    loaded_scenes.push_back(text.str());
  }
}

// Reads a whole argument as a finite double; false for anything else.
bool parse_finite(const std::string& text, double& value) {
  try {
    std::size_t used = 0;
    value = std::stod(text, &used);
    return used == text.size() && std::isfinite(value);
  } catch (const std::exception&) {
    return false;
  }
}
}  // namespace

CLI::Validator finite_number(bool allow_zero) {
  return CLI::Validator(
      [allow_zero](std::string& text) -> std::string {
        double value = 0.0;
        if (parse_finite(text, value) && (value > 0.0 || (allow_zero && value == 0.0))) return {};
        return std::string("must be a finite number ") + (allow_zero ? ">= 0" : "> 0") + " (got " + text + ")";
      },
      allow_zero ? "NUMBER >= 0" : "NUMBER > 0");
}

CLI::Validator finite_in(double low, double high) {
  return CLI::Validator(
      [low, high](std::string& text) -> std::string {
        double value = 0.0;
        if (parse_finite(text, value) && value >= low && value <= high) return {};
        std::ostringstream message;
        message << "must be a finite number in [" << low << ", " << high << "] (got " << text << ")";
        return message.str();
      },
      "NUMBER");
}

namespace {
// The name of integer_in's validators, by which Option::range finds one to replace.
constexpr const char* kIntegerRange = "integer range";

// A whole argument read as an integer in [low, high]; `name` is what --help shows.
CLI::Validator integer_check(long long low, long long high, const std::string& name) {
  return CLI::Validator(
      [low, high](std::string& text) -> std::string {
        const std::string range = "[" + std::to_string(low) + ", " + std::to_string(high) + "]";
        long long value = 0;
        std::size_t used = 0;
        try {
          value = std::stoll(text, &used);
        } catch (const std::invalid_argument&) {
          used = 0;
        } catch (const std::out_of_range&) {
          return text + " is not in " + range;
        }
        if (used == 0 || used != text.size()) return "'" + text + "' is not an integer";
        if (value < low || value > high) return text + " is not in " + range;
        return {};
      },
      name);
}

// Any integer the option's type holds; no text in --help (the type says INT).
CLI::Validator any_integer(long long low, long long high) { return integer_check(low, high, ""); }
}  // namespace

CLI::Validator integer_in(long long low, long long high) {
  CLI::Validator check = integer_check(low, high, "[" + std::to_string(low) + ", " + std::to_string(high) + "]");
  check.name(kIntegerRange).non_modifying();
  return check;
}

CommonOptions lab_defaults(std::string scene, std::string method, std::vector<std::string> methods) {
  CommonOptions options;
  options.scene = std::move(scene);
  options.method = std::move(method);
  options.methods = std::move(methods);
  return options;
}

void add_common_options(CLI::App& app, CommonOptions& options, unsigned flags) {
  if (flags & kFlagScene) {
    app.add_option("--scene", options.scene, "scene file (.json) or the name of a shipped scene")
        ->capture_default_str();
  }
  if (flags & kFlagMethod) {
    app.add_option("--method", options.method, "solver method")
        ->check(CLI::IsMember(options.methods))
        ->capture_default_str();
  }
  if (flags & kFlagIterations) {
    app.add_option("--iterations", options.iterations, "solver iterations per step (0 allowed)")
        ->check(integer_in(0, 100'000'000))
        ->capture_default_str();
  }
  if (flags & kFlagDt) {
    // The scene's own range and words (limits in common/scene.h): a step of 1e300 s overflows g Δt².
    const CLI::Validator dt_range(
        [](std::string& text) -> std::string {
          double value = 0.0;
          if (parse_finite(text, value) && limits::kDt.contains(value)) return {};
          return "must be in " + limits::kDt.text() + " (got " + text + ")";
        },
        limits::kDt.text());
    app.add_option("--dt", options.dt, "time step in seconds (default: the scene's)")->check(dt_range);
  }
  if (flags & kFlagSteps) {
    app.add_option("--steps", options.steps, "number of time steps (default: the scene's)")
        ->check(integer_in(0, limits::kMaxSteps));
  }
  if (flags & kFlagOut) app.add_option("--out", options.out, "directory for the CSV files");
  if (flags & kFlagSummary) app.add_option("--summary", options.summary, "write the run summary (JSON) here");
  if (flags & kFlagFrames) {
    app.add_option("--frames", options.frames,
                   options.frames_are_sweeps
                       ? "keep every N-th sweep in OUT/trajectory.json and .bin (./course view OUT)"
                       : "keep every N-th frame in OUT/trajectory.json and .bin (./course view OUT)")
        ->check(integer_in(1, 100'000'000));
  }
}

Option& Option::range(long long low, long long high) {
  // A range given to a common flag (--iterations' [0, 1e8]) replaces it, so
  // that the refusal and --help state the range that holds.
  CLI::Validator* existing = nullptr;
  try {
    existing = option_->get_validator(kIntegerRange);
  } catch (const CLI::OptionNotFound&) {
  }
  if (existing != nullptr) {
    *existing = integer_in(low, high);
  } else {
    option_->check(integer_in(low, high));
  }
  return *this;
}

Option& Option::one_of(const std::vector<std::string>& words) {
  option_->check(CLI::IsMember(words));
  return *this;
}

Option& Option::positive() {
  option_->check(finite_number(false));
  return *this;
}

Option& Option::non_negative() {
  option_->check(finite_number(true));
  return *this;
}

Option& Option::finite_in(double low, double high) {
  option_->check(cl::finite_in(low, high));
  return *this;
}

Option& Option::delimiter(char separator) {
  option_->delimiter(separator);
  return *this;
}

Option& Option::capture_default_str() {
  option_->capture_default_str();
  return *this;
}

Option& Option::description(const std::string& text) {
  option_->description(text);
  return *this;
}

Option& Option::excludes(const Option& other) {
  option_->excludes(other.option_);
  return *this;
}

Option& Option::only_for_methods(std::vector<std::string> methods) {
  if (line_ == nullptr) throw std::logic_error("Option::only_for_methods: an option of a CommandLine only");
  line_->method_flags_.push_back({option_, std::move(methods)});
  return *this;
}

Option& Option::only_for_modes(std::vector<std::string> modes) {
  if (line_ == nullptr) throw std::logic_error("Option::only_for_modes: an option of a CommandLine only");
  line_->mode_flags_.push_back({option_, std::move(modes)});
  return *this;
}

void CommandLine::add_mode(const std::string& name) { modes_.push_back(app_->get_option(name)); }

void CommandLine::modes(const std::vector<std::pair<std::string, std::vector<std::string>>>& modes,
                        const std::vector<std::string>& run_only) {
  std::vector<std::pair<std::string, std::vector<std::string>>> readers;  // option, the modes that read it
  auto add = [&](const std::string& option, const std::string& mode) {
    for (auto& entry : readers) {
      if (entry.first == option) return entry.second.push_back(mode);
    }
    readers.push_back({option, {mode}});
  };
  for (const auto& [mode, options] : modes) {
    add_mode(mode);
    for (const std::string& option : options) add(option, mode);
  }
  for (const std::string& option : run_only) add(option, "run");
  for (const auto& [option, readers_of] : readers) get_option(option).only_for_modes(readers_of);
}

CommandLine::CommandLine(const std::string& description, const std::string& program_name)
    : app_(std::make_unique<CLI::App>(description, program_name)) {}

CommandLine::~CommandLine() = default;

Option CommandLine::add_option(const std::string& name, std::string& value, const std::string& help) {
  return Option(app_->add_option(name, value, help), this);
}

// Integers are checked as text before CLI11 converts them, so that "abc"
// reads "'abc' is not an integer" rather than CLI11's "Value abc not in range".
Option CommandLine::add_option(const std::string& name, int& value, const std::string& help) {
  return Option(app_->add_option(name, value, help)->check(any_integer(INT_MIN, INT_MAX)), this);
}

Option CommandLine::add_option(const std::string& name, long long& value, const std::string& help) {
  return Option(app_->add_option(name, value, help)->check(any_integer(LLONG_MIN, LLONG_MAX)), this);
}

Option CommandLine::add_option(const std::string& name, double& value, const std::string& help) {
  return Option(app_->add_option(name, value, help), this);
}

Option CommandLine::add_option(const std::string& name, std::optional<double>& value, const std::string& help) {
  return Option(app_->add_option(name, value, help), this);
}

Option CommandLine::add_option(const std::string& name, std::vector<int>& values, const std::string& help) {
  return Option(app_->add_option(name, values, help)->check(any_integer(INT_MIN, INT_MAX)), this);
}

Option CommandLine::add_option(const std::string& name, std::vector<double>& values, const std::string& help) {
  return Option(app_->add_option(name, values, help), this);
}

Option CommandLine::add_option(const std::string& name, std::vector<std::string>& values, const std::string& help) {
  return Option(app_->add_option(name, values, help), this);
}

Option CommandLine::add_flag(const std::string& name, bool& value, const std::string& help) {
  return Option(app_->add_flag(name, value, help), this);
}

Option CommandLine::get_option(const std::string& name) { return Option(app_->get_option(name), this); }

void CommandLine::refuse_unused_flags() const {
  for (const MethodFlag& flag : method_flags_) {
    if (flag.option->count() == 0) continue;
    if (method_ == nullptr) throw std::logic_error(flag.option->get_name() + ": only_for_methods needs --method");
    if (std::find(flag.methods.begin(), flag.methods.end(), *method_) != flag.methods.end()) continue;
    std::string users;
    for (const std::string& method : flag.methods) users += (users.empty() ? "" : ", ") + method;
    throw InputError(flag.option->get_name() + ": --method " + *method_ + " does not use it (only " + users +
                     (flag.methods.size() == 1 ? " does)" : " do)"));
  }
  std::vector<std::string> active;
  for (const CLI::Option* mode : modes_) {
    if (mode->count() > 0) active.push_back(mode->get_name());
  }
  const std::string current = active.empty() ? std::string("a run") : active.front();
  if (active.empty()) active.push_back("run");
  method_read_here = true;
  for (const MethodFlag& flag : mode_flags_) {
    if (flag.option->get_name() != "--method") continue;
    method_read_here = false;
    for (const std::string& mode : active) {
      if (std::find(flag.methods.begin(), flag.methods.end(), mode) != flag.methods.end()) method_read_here = true;
    }
  }
  for (const MethodFlag& flag : mode_flags_) {
    if (flag.option->count() == 0) continue;
    bool read = false;
    for (const std::string& mode : active) {
      read = read || std::find(flag.methods.begin(), flag.methods.end(), mode) != flag.methods.end();
    }
    if (read) continue;
    std::string readers;
    for (const std::string& mode : flag.methods) readers += (readers.empty() ? "" : ", ") + (mode == "run" ? "a run" : mode);
    throw InputError(flag.option->get_name() + ": " + current + " does not read it (only " + readers +
                     (flag.methods.size() == 1 ? " does)" : " do)"));
  }
}

void add_common_options(CommandLine& line, CommonOptions& options, unsigned flags) {
  add_common_options(line.app(), options, flags);
  if (flags & kFlagMethod) line.method_ = &options.method;
}

Scene load_scene_for(const CommonOptions& options, const std::string& lab_scene_dir, const std::string& flag) {
  Scene scene = load_scene(resolve_scene_path(options.scene, lab_scene_dir, flag));
  if (!options.models_colliders && !scene.colliders.empty()) {
    throw InputError(scene.source + ": colliders[0]: this lab does not model colliders (lab 14 does: lab14_contact)");
  }
  if (options.dt > 0.0) scene.dt = options.dt;
  if (options.steps >= 0) scene.steps = options.steps;
  if (options.frames > 0) {
    if (options.out.empty()) throw InputError("--frames: needs --out DIR (the trajectory goes to OUT/trajectory.*)");
    check_trajectory_size(scene, options.frames_are_sweeps ? options.iterations : scene.steps, options.frames);
  }
  note_scene(scene);
  return scene;
}

void start_run(const CommonOptions& options) {
  if (check_mode()) {
    std::string line;
    if (!options.method.empty() && method_read_here) line += ", --method " + options.method;
    if (!options.out.empty()) line += ", writes " + options.out + "/";
    if (!options.summary.empty()) line += ", summary " + options.summary;
    throw CheckStop{line};
  }
  ensure_directory(options.out);
}

void start_run(const std::string& out_dir) {
  if (check_mode()) throw CheckStop{out_dir.empty() ? std::string() : ", writes " + out_dir + "/"};
  ensure_directory(out_dir);
}

namespace {
// "lab01_single_spring lab02_gauss_seidel" -> "lab 01, lab 02"
std::string lab_numbers(const std::string& labs) {
  std::istringstream names(labs);
  std::string name, text;
  while (names >> name) {
    if (!text.empty()) text += ", ";
    text += "lab " + name.substr(3, 2);
  }
  return text;
}

int noting(int code, const std::string& program, const char* student_earlier_labs) {
  const std::string labs = lab_numbers(student_earlier_labs ? student_earlier_labs : "");
  if (!labs.empty()) {
    std::cerr << program << ": note: runs your own code of " << labs
              << " (no reference in solutions/ yet; docs/DESIGN.md §4)\n";
  }
  return code;
}
}  // namespace

namespace {
// "unknown option --rho (options: --scene, --method, ...)" for CLI11's "The
// following arguments were not expected: 0.5 --rho": the first word that
// looks like an option names it; a stray value is named as one.
std::string unknown_option_line(const CLI::App& app, int argc, char** argv) {
  std::string options;
  for (const CLI::Option* option : app.get_options()) {
    const std::string name = option->get_name();
    if (name.rfind("--", 0) == 0 && name != "--help") options += (options.empty() ? "" : ", ") + name;
  }
  for (int i = 1; i < argc; ++i) {
    std::string word = argv[i];
    if (word.rfind("--", 0) != 0) continue;
    const std::string name = word.substr(0, word.find('='));
    if (app.get_option_no_throw(name) == nullptr) return "unknown option " + name + " (options: " + options + ")";
  }
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word.rfind("-", 0) == 0) continue;
    bool value = i > 1 && std::string(argv[i - 1]).rfind("--", 0) == 0;
    if (!value) return "unexpected argument '" + word + "' (options: " + options + ")";
  }
  return "unexpected arguments (options: " + options + ")";
}
// An option given an empty value ("--stiffness ''"), or a list option
// (delimiter) with an empty item ("--compare-pbd 1,,2", "1,", ",2"): the line
// that refuses it, or "" when there is none. CLI11 would drop the empty item
// (or take the empty value as absent) and run something the user did not ask for.
std::string empty_value_line(const CLI::App& app, int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    std::string word = argv[i];
    if (word.rfind("--", 0) != 0) continue;
    std::string value;
    const std::size_t equals = word.find('=');
    if (equals != std::string::npos) {
      value = word.substr(equals + 1);
      word.resize(equals);
    } else if (i + 1 < argc && std::string(argv[i + 1]).rfind("--", 0) != 0) {
      value = argv[i + 1];
    } else {
      continue;  // no value here: CLI11 says what is missing
    }
    const CLI::Option* option = app.get_option_no_throw(word);
    if (option == nullptr || option->get_type_size() == 0) continue;  // unknown (CLI11's line), or a flag
    if (value.empty()) return word + ": empty (give a value; see --help)";
    const char separator = option->get_delimiter();
    if (separator == '\0') continue;
    std::size_t item = 0;
    std::size_t start = 0;
    for (;; ++item) {
      const std::size_t end = value.find(separator, start);
      if ((end == std::string::npos ? value.size() : end) == start) {
        return word + "[" + std::to_string(item) + "]: empty (in '" + value + "'; a list is VALUE" + separator +
               "VALUE...)";
      }
      if (end == std::string::npos) break;
      start = end + 1;
    }
  }
  return "";
}
}  // namespace

int run_main(CLI::App& app, int argc, char** argv, const std::function<int()>& body,
             const char* student_earlier_labs) {
  const std::string program = app.get_name();
  std::vector<const char*> words(argv, argv + argc);
  if (!words.empty()) words[0] = program.c_str();
  set_command_line(argc, words.data());
  bool check = false;
  loaded_scenes.clear();  // one run's scenes (a test calls run_main many times in one process)
  method_read_here = true;
  if (app.get_option_no_throw("--check") == nullptr) {
    app.add_flag("--check", check,
                 "check the flags and the scene as a run would, print what would run, and stop (nothing written)");
  }
  if (const std::string empty = empty_value_line(app, argc, argv); !empty.empty()) {
    std::cerr << program << ": " << empty << "\n";
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ExtrasError& error) {
    std::cerr << program << ": " << unknown_option_line(app, argc, argv) << "\n";
    return 2;
  } catch (const CLI::CallForHelp&) {
    std::cout << app.help();
    return 0;
  } catch (const CLI::CallForAllHelp&) {
    std::cout << app.help("", CLI::AppFormatMode::All);
    return 0;
  } catch (const CLI::ParseError& error) {
    std::cerr << program << ": " << error.what() << " (see --help)\n";
    return 2;
  }
  set_check_mode(check);
  try {
    return noting(body(), program, student_earlier_labs);
  } catch (const CheckStop& stop) {
    std::string scenes;
    for (const std::string& scene : loaded_scenes) scenes += (scenes.empty() ? "" : "; ") + scene;
    std::cout << program << ": check: ok, would run " << (scenes.empty() ? std::string("(no scene)") : scenes)
              << stop.detail << "\n";
    return 0;
  } catch (const InputError& error) {
    std::cerr << program << ": " << error.what() << "\n";
    return 2;
  } catch (const NotImplemented& error) {
    std::cerr << program << ": " << error.what() << "; write it, then run again\n";
    return noting(3, program, student_earlier_labs);
  } catch (const std::invalid_argument& error) {
    std::cerr << program << ": invalid argument: " << error.what() << "\n";
    return 2;
  } catch (const std::exception& error) {
    std::cerr << program << ": error: " << error.what() << "\n";
    return noting(1, program, student_earlier_labs);
  }
}

int run_main(CommandLine& line, int argc, char** argv, const std::function<int()>& body,
             const char* student_earlier_labs) {
  // The unused flags are refused before the body runs: nothing is written.
  return run_main(line.app(), argc, argv, [&] {
    line.refuse_unused_flags();
    return body();
  }, student_earlier_labs);
}

}  // namespace cl
