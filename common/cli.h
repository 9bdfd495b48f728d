#pragma once
// The command line shared by every lab executable (docs/DESIGN.md §3) and the
// wrapper that turns every failure into one line on stderr and an exit code:
//   0 done, 2 bad input or usage, 3 a student function not implemented yet.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/scene.h"

// Declared, not included: CLI11 is header-only, so every file that includes it
// compiles its validators and whatever of its App it uses: a lab's main.cpp
// took 15 s of CPU at -O3 with CLI11, 4 s without. The labs' drivers build
// their command line through CommandLine below, which common/cli.cpp compiles
// once; only cli.cpp and its test include <CLI/CLI.hpp>.
namespace CLI {
class App;
class Option;
class Validator;
}  // namespace CLI

// A lab's main.cpp is compiled once for both of its executables (NAME and
// NAME_solution); each executable links a generated source (cmake/AddLab.cmake)
// that defines who it is: its name, and the earlier labs whose reference is not
// in solutions/ yet, so that it runs the student's own code for them
// (space-separated, docs/DESIGN.md §4). A driver sees them as CL_PROGRAM_NAME
// and CL_STUDENT_EARLIER_LABS; elsewhere the latter is empty.
extern "C" const char cl_program_name[];
extern "C" const char cl_student_earlier_labs[];
#ifndef CL_STUDENT_EARLIER_LABS
#define CL_STUDENT_EARLIER_LABS ""
#endif

namespace cl {

// Which of the shared flags a lab takes; a lab only offers what it uses.
enum CommonFlag : unsigned {
  kFlagScene = 1u << 0,       // --scene FILE.json | NAME
  kFlagMethod = 1u << 1,      // --method M
  kFlagIterations = 1u << 2,  // --iterations K
  kFlagDt = 1u << 3,          // --dt S
  kFlagSteps = 1u << 4,       // --steps N
  kFlagOut = 1u << 5,         // --out DIR
  kFlagSummary = 1u << 6,     // --summary FILE.json
  kFlagFrames = 1u << 7,      // --frames N: the trajectory (common/trajectory.h)
};

struct CommonOptions {
  std::string scene;                 // name or path, as given
  std::string method;
  std::vector<std::string> methods;  // the choices for --method
  int iterations = 10;
  double dt = 0.0;                   // 0: the scene's
  int steps = -1;                    // -1: the scene's
  std::string out;                   // empty: no CSV files
  std::string summary;               // empty: no summary file
  int frames = 0;                    // keep every N-th frame in OUT/trajectory.*; 0: none
  // A sweep lab (02, 03) keeps one frame per sweep: its last frame is
  // --iterations, not the scene's steps (the trajectory's size check).
  bool frames_are_sweeps = false;
  // Only lab 14 models colliders: every other lab refuses a scene that
  // declares them (load_scene_for), rather than letting the cloth pass through.
  bool models_colliders = false;
};

// The common options with a lab's defaults: its --scene and, for a lab that
// takes --method, the default method and the choices (in the order --help lists them).
CommonOptions lab_defaults(std::string scene, std::string method = {}, std::vector<std::string> methods = {});

// A CLI11 check: a finite number > 0 (or >= 0 with allow_zero). Unlike CLI11's
// own checks it rejects inf and nan and keeps the message to one short line.
CLI::Validator finite_number(bool allow_zero);

// A CLI11 check: a finite number in [low, high] (CLI::Range lets "nan" through).
CLI::Validator finite_in(double low, double high);

// A CLI11 check: the whole argument an integer in [low, high]; its message is
// one short line, "'abc' is not an integer" or "0 is not in [1, 16]" (CLI11's
// Range says "Value abc not in range" for both).
CLI::Validator integer_in(long long low, long long high);

// Registers the flags in `flags` on `app`. Set the defaults in `options`
// (scene, method, methods, iterations) before calling.
void add_common_options(CLI::App& app, CommonOptions& options, unsigned flags);

// Loads the scene named by --scene for a lab whose scenes live in
// lab_scene_dir, and applies --dt and --steps. With --frames N it also refuses
// a run without --out and one whose trajectory would be over the size cap
// (check_trajectory_size), before anything is written. A scene with colliders
// is refused ("<file>: colliders[0]: this lab does not model colliders (lab 14
// does)") unless options.models_colliders. Throws InputError; an
// unknown name is blamed on `flag` (--sweep-scenes, for a sweep's scenes).
Scene load_scene_for(const CommonOptions& options, const std::string& lab_scene_dir,
                     const std::string& flag = "--scene");

// Where a run starts, once all of its input is checked: under --check the
// run stops here (run_main prints what would run: the scenes loaded, the
// method, the files it would write; exit 0, nothing written); otherwise it
// makes --out's folder, so that a refusal before it leaves nothing behind.
void start_run(const CommonOptions& options);
void start_run(const std::string& out_dir);  // a driver without CommonOptions' --out (lab 01's --sweep)


// One option of a CommandLine, for chaining its checks and help, in CLI11's
// terms: app.add_option("--seed", seed, "...").range(0, 1000).capture_default_str().
class CommandLine;

class Option {
 public:
  explicit Option(CLI::Option* option, CommandLine* line = nullptr) : option_(option), line_(line) {}
  // An integer in [low, high] (integer_in); on a common flag that has a range
  // already (--iterations), it replaces it.
  Option& range(long long low, long long high);
  Option& one_of(const std::vector<std::string>& words);       // one of these words (CLI::IsMember)
  Option& positive();                                          // finite_number(false): finite, > 0
  Option& non_negative();                                      // finite_number(true): finite, >= 0
  Option& finite_in(double low, double high);                  // finite_in(low, high)
  Option& delimiter(char separator);                           // a list: "1,2,3"
  Option& capture_default_str();                               // --help shows the default
  Option& description(const std::string& text);
  Option& excludes(const Option& other);                       // not together with `other`
  // Only these --method choices read the option: given with another, it is
  // refused before the run (exit 2, one line: "--rho: --method pd does not
  // use it (only pd-chebyshev, jacobi-chebyshev do)"), not silently ignored.
  Option& only_for_methods(std::vector<std::string> methods);
  // Only these modes read the option: a mode is a flag or list option declared
  // by CommandLine::add_mode (--convergence, --sweep-iterations), and "run" is
  // the program without any. Given in another mode it is refused before the
  // run ("--steps: --convergence does not read it (only a run does)").
  Option& only_for_modes(std::vector<std::string> modes);

 private:
  CLI::Option* option_;
  CommandLine* line_;
};

// A lab's command line: a CLI::App behind an interface that takes the option
// types the labs use, so that no driver instantiates CLI11's templates.
class CommandLine {
 public:
  CommandLine(const std::string& description, const std::string& program_name);
  ~CommandLine();
  CommandLine(const CommandLine&) = delete;
  CommandLine& operator=(const CommandLine&) = delete;

  Option add_option(const std::string& name, std::string& value, const std::string& help);
  Option add_option(const std::string& name, int& value, const std::string& help);
  Option add_option(const std::string& name, long long& value, const std::string& help);
  Option add_option(const std::string& name, double& value, const std::string& help);
  Option add_option(const std::string& name, std::optional<double>& value, const std::string& help);  // unset: not given
  Option add_option(const std::string& name, std::vector<int>& values, const std::string& help);
  Option add_option(const std::string& name, std::vector<double>& values, const std::string& help);
  Option add_option(const std::string& name, std::vector<std::string>& values, const std::string& help);
  Option add_flag(const std::string& name, bool& value, const std::string& help);
  Option get_option(const std::string& name);  // one already added (a common flag's help, say)

  CLI::App& app() { return *app_; }

  // Declares an option (added already) as a mode of the program, for
  // Option::only_for_modes: the mode is on when the option is given.
  void add_mode(const std::string& name);

  // The program's modes in one call: each mode option (added already) with the
  // options only it reads, and the options only a plain run reads; the rest
  // are read in every mode. Short for add_mode and only_for_modes.
  void modes(const std::vector<std::pair<std::string, std::vector<std::string>>>& modes,
             const std::vector<std::string>& run_only);

  // Throws InputError for the first option given with a --method that its
  // only_for_methods list leaves out, or in a mode that its only_for_modes
  // list leaves out; run_main calls it after parsing.
  void refuse_unused_flags() const;

 private:
  friend class Option;
  friend void add_common_options(CommandLine& line, CommonOptions& options, unsigned flags);
  struct MethodFlag {
    CLI::Option* option;
    std::vector<std::string> methods;
  };
  std::unique_ptr<CLI::App> app_;
  std::vector<MethodFlag> method_flags_;
  std::vector<MethodFlag> mode_flags_;     // an option and the modes that read it
  std::vector<CLI::Option*> modes_;        // the options that select a mode
  const std::string* method_ = nullptr;  // the --method value (add_common_options with kFlagMethod)
};

// With kFlagMethod it also tells `line` where --method's choice lands, for
// Option::only_for_methods.
void add_common_options(CommandLine& line, CommonOptions& options, unsigned flags);

// Parses the command line and runs `body`, mapping every failure to a single
// stderr line and exit code: CLI and InputError -> 2, NotImplemented -> 3,
// anything else -> 1. `body` returns the exit code for a run that finished.
// With a CommandLine, the options given to a method that does not use them are
// refused first (refuse_unused_flags), before `body` writes anything.
// Every program takes --check (docs/DESIGN.md §3): the body runs until
// start_run (or any first write or step), which under --check stops it; the
// one line "PROGRAM: check: would run ..." goes to stdout, exit 0.
// An unknown option is refused as "unknown option --rho" with the program's
// options listed.
// A run that gets past its input (exit 0, 1 or 3) and links the student's code
// of earlier labs (`student_earlier_labs`) says so in one more stderr line; a
// refusal (exit 2) stays one line.
int run_main(CLI::App& app, int argc, char** argv, const std::function<int()>& body,
             const char* student_earlier_labs = CL_STUDENT_EARLIER_LABS);
int run_main(CommandLine& line, int argc, char** argv, const std::function<int()>& body,
             const char* student_earlier_labs = CL_STUDENT_EARLIER_LABS);

}  // namespace cl
