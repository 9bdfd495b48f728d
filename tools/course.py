"""Constraint Labs driver: build, demo, test, grade, run, plots, bench.

Started by ../course, which installs the Debian packages and picks a Python
with matplotlib. Paths are relative to the course root, not the cwd.
"""
import argparse
import json
import os
import shlex
import shutil
import subprocess
import re
import sys
import tempfile
import time
from pathlib import Path

import grade

ROOT = Path(__file__).resolve().parent.parent
BUILD = ROOT / os.environ.get("CL_BUILD_DIR", "build")
BIN = BUILD / "bin"
PLOT_SKIPPED = 4  # a plot script's exit code when its input is not in DIR
PLOT_ERROR_LINES = 12  # of a failing plot script's stderr, shown

USAGE = """\
usage: ./course COMMAND [ARGS]

  demo [--out DIR]                   every lab's demo with the reference code -> DIR (out/)
  test                               unit tests, grading honesty, demo and plots (CI)
  grade [labNN ...] [-t PATTERN] [-v] [--solutions] [--output FILE]
                                     graded tests (each lab built on its own): Score: X/Y,
                                     build/grade/results.json; -t: only matching cases,
                                     -v: list passing cases too
  release labNN DIR                  the student tree for lab NN's week: stubs, and the
                                     reference code of the labs before NN
  autograder labNN [--out FILE.zip]  the Gradescope autograder for lab NN (its hidden tests
                                     too): build/gradescope/labNN.zip
  run labNN [ARGS]                   one lab executable (your code); labNN_solution: the reference
  plots [DIR]                        figures from the CSV/JSON in DIR (out/)
  bench [--quick] [--micro ARGS]     the speed/accuracy trade of every method -> out/bench (bench/README.md)
  extremes [--quick]                 the extremes matrix: finite, reported or silent NaN -> out/bench
  fuzz [SECONDS]                     fuzz the scene loader with libFuzzer (clang; default 60 s)
  sanitize                           the whole test suite under AddressSanitizer and UBSan (build/asan)
  help                               this text

Paths are relative to the course root; CL_BUILD_DIR overrides build/."""


class CourseError(Exception):
    """A problem the user can fix: its details (a program's stderr), one line, exit `code`."""

    def __init__(self, message, code=1, details=()):
        super().__init__(message)
        self.code = code
        self.details = list(details)


def show(path):
    """A path as the user should read it: relative to the course root when inside it."""
    return grade.relative(path, ROOT)


def under_root(path):
    return ROOT / path  # an absolute `path` stays as it is


# ---------------------------------------------------------------- build
#
# One configure, then per-lab builds: `./course grade lab01` builds only the
# targets lab 01's grading needs, so a compile error in another lab blocks
# nothing else. CMake writes build/labs.json (cmake/AddLab.cmake): per lab its
# student files, whether it has a reference, its earlier labs and which of them
# the graded tests link as reference or as the student's code.

MANIFEST = BUILD / "labs.json"
ERROR_LINES = 14  # of a failed build, shown
WARNING_LINES = 3  # of the warnings in a student's files, shown


class BuildFailure(Exception):
    """Targets that did not build; `lines` is the compiler's first errors."""

    def __init__(self, targets, lines):
        super().__init__(f"{' '.join(targets)} did not build")
        self.lines = lines


def configure(log=sys.stdout, force=False):
    """Configure BUILD when it is new or its lab manifest is out of date."""
    if force or not (BUILD / "CMakeCache.txt").is_file() or manifest_stale():
        print("configuring...", end=" ", file=log, flush=True)
        start = time.monotonic()
        try:
            quiet(["cmake", "-S", str(ROOT), "-B", str(BUILD), "-DCMAKE_BUILD_TYPE=Release"], "configure")
        finally:
            print(f"{time.monotonic() - start:.1f} s", file=log, flush=True)


def manifest():
    """build/labs.json's "labs": {lab: {student, reference, info, deps, links}}."""
    try:
        return json.loads(MANIFEST.read_text())["labs"]
    except (OSError, ValueError, KeyError):
        return {}


def manifest_stale():
    """True when a lab or a reference appeared or went since the last configure."""
    labs = manifest()
    if not labs:
        return True
    declared = (ROOT / "CMakeLists.txt").read_text()
    if any(lab not in labs and f"add_lab({lab} " in declared for lab in lab_dirs()):
        return True
    for lab, entry in labs.items():
        present = all((ROOT / "solutions" / lab / Path(f).name).is_file() for f in entry["student"])
        if present != entry["reference"]:
            return True
    return False


def build(log=sys.stdout):
    """Configure (first time) and build everything; show the output only on failure."""
    configure(log)
    print("building...", end=" ", file=log, flush=True)
    start = time.monotonic()
    try:
        quiet(["cmake", "--build", str(BUILD), "-j", "2"], "build")
    finally:
        print(f"{time.monotonic() - start:.1f} s", file=log, flush=True)


def quiet(command, what):
    try:
        done = subprocess.run(command, cwd=ROOT, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True, check=False)
    except FileNotFoundError:
        raise CourseError(f"{command[0]} not found; ./course installs it") from None
    if done.returncode != 0:
        raise CourseError(f"{what} failed (cmake exit code {done.returncode})",
                          details=done.stdout.splitlines())


def build_targets(targets, build_dir=None, log=sys.stdout, label=None):
    """Build only `targets`; return the tools' output. Raise BuildFailure."""
    build_dir = build_dir or BUILD
    if log is not None:
        print(f"building {label or ' '.join(targets)}...", end=" ", file=log, flush=True)
    start = time.monotonic()
    try:
        done = subprocess.run(["cmake", "--build", str(build_dir), "-j", "2", "--target", *targets],
                              cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                              check=False)
    except FileNotFoundError:
        raise CourseError("cmake not found; ./course installs it") from None
    finally:
        if log is not None:
            print(f"{time.monotonic() - start:.1f} s", file=log, flush=True)
    if done.returncode != 0:
        raise BuildFailure(targets, first_errors(done.stdout))
    return done.stdout


def first_errors(output):
    """The compiler's first errors in a build log, paths relative to the root."""
    lines = [line for line in output.splitlines()
             if not re.match(r"^(\[\s*\d+%\]|gmake|make|Scanning|Consolidate|Built target)", line)
             and "Error 1" not in line and "Error 2" not in line]
    start = next((i for i, line in enumerate(lines)
                  if re.search(r"\b(error|Error|undefined reference)\b", line)), None)
    if start is None:
        shown = lines[-ERROR_LINES:]
    else:
        # Keep the "In function ..." line that introduces the first error.
        if start > 0 and re.search(r"In (member )?function|In file included", lines[start - 1]):
            start -= 1
        shown = lines[start:start + ERROR_LINES]
    return [line.replace(str(ROOT) + "/", "") for line in shown]


def lab_targets(lab, solutions=False):
    """The targets grading `lab` needs: its graded tests (and its info program)."""
    entry = manifest().get(lab, {})
    suffix = "_solution" if solutions else ""
    targets = [f"{lab}_tests{suffix}"]
    if entry.get("info"):
        targets.append(f"{lab}_info{suffix}")
        if not solutions and entry.get("reference"):
            targets.append(f"{lab}_info_solution")
    return targets


def student_warnings(lab, output):
    """Warnings in the lab's student files: from this build's output for the
    files it recompiled, remembered from the last compile for the others."""
    cache = BUILD / "grade" / "warnings"
    cache.mkdir(parents=True, exist_ok=True)
    found = []
    for student in manifest().get(lab, {}).get("student", []):
        remembered = cache / (student.replace("/", "__") + ".txt")
        if f"CMakeFiles/{lab}_student.dir/{student}.o" in output:
            path = str(ROOT / student)
            lines = [line.replace(str(ROOT) + "/", "") for line in output.splitlines()
                     if line.startswith(path + ":") and ": warning:" in line]
            remembered.write_text("".join(line + "\n" for line in lines))
        if remembered.is_file():
            found += remembered.read_text().splitlines()
    return found


def sanitizer_env(leaks):
    """The environment of a sanitizer run. allow_user_segv_handler=0: Catch2 may not
    take SIGSEGV/SIGABRT from the sanitizer, whose report then shows the faulting
    line, not a re-raise."""
    return dict(os.environ,
                ASAN_OPTIONS=f"detect_leaks={int(leaks)}:allow_user_segv_handler=0:handle_abort=1",
                UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1")


def sanitizer_rerun(lab, case, log=sys.stdout):
    """Rerun one crashed case in NAME_tests_asan (cmake/AddLab.cmake: the tests and
    the student's code under -fsanitize=address,undefined -g -O1); lines saying
    where it failed."""
    target = f"{lab}_tests_asan"
    try:
        build_targets([target], log=log, label=f"{target} (-fsanitize=address,undefined)")
    except BuildFailure as failure:
        return ["the sanitizer build failed:", *failure.lines[:4]]
    binary = BIN / target
    # A crash is what is asked about here, so leaks are not reported.
    env = sanitizer_env(leaks=False)
    with tempfile.TemporaryDirectory(prefix="cl-asan-") as work:
        try:
            done = subprocess.run([str(binary), case.name], cwd=work, env=env, capture_output=True,
                                  text=True, timeout=grade.CASE_TIMEOUT, check=False)
        except subprocess.TimeoutExpired:
            return ["the sanitizer run timed out"]
    lines = grade.sanitizer_report(done.stdout + done.stderr, ROOT)
    return lines or [f"the sanitizer build ran the case without a report (exit code {done.returncode})"]


# ---------------------------------------------------------------- labs

def lab_dirs():
    """Lab directory names, labs/labNN_*, sorted."""
    return sorted(p.name for p in (ROOT / "labs").glob("lab[0-9][0-9]_*") if p.is_dir())


def resolve_lab(token):
    """`lab01` or `lab01_single_spring` -> `lab01_single_spring`."""
    for lab in lab_dirs():
        if token in (lab, grade.lab_id(lab)):
            return lab
    known = ", ".join(grade.lab_id(lab) for lab in lab_dirs()) or "none yet"
    raise CourseError(f"unknown lab '{token}' (labs: {known})", code=2)


def executable(name):
    path = BIN / name
    if not path.is_file():
        raise CourseError(f"{show(path)} not found (is it added in CMakeLists.txt?)")
    return path


# ---------------------------------------------------------------- demo

def demo_lines(lab):
    """The argument lists in labs/LAB/demo.txt."""
    demo = ROOT / "labs" / lab / "demo.txt"
    if not demo.is_file():
        return []
    lines = (line.strip() for line in demo.read_text().splitlines())
    return [shlex.split(line) for line in lines if line and not line.startswith("#")]


def run_demos(out, echo=True, labs=None, student_fallback=True):
    """Run the demo lines of `labs` (default: every lab) into OUT/<lab> with the
    reference executable, or the student's where the lab has no reference (when
    `student_fallback`, else the lab is skipped). Raise on the first failure."""
    configure()
    entries = manifest()
    labs = [lab for lab in (labs or lab_dirs()) if demo_lines(lab) and lab in entries]
    if not labs:
        print("no lab has a demo.txt yet")
    for lab in labs:
        reference = entries[lab]["reference"]
        if not reference and not student_fallback:
            print(f"  {lab}: no reference here, demo skipped")
            continue
        if not reference:
            print(f"  {lab}: no reference here, the demo runs your code")
        name = lab + ("_solution" if reference else "")
        try:
            build_targets([name], log=None)
        except BuildFailure as failure:
            raise CourseError(f"{name} does not build", details=failure.lines) from None
        program = executable(name)
        lab_out = out / lab
        lab_out.mkdir(parents=True, exist_ok=True)
        for args in demo_lines(lab):
            shown = shlex.join([program.name, *(a.replace("{out}", show(lab_out)) for a in args)])
            if echo:
                print("  " + shown, flush=True)
            argv = [str(program), *(arg.replace("{out}", str(lab_out)) for arg in args)]
            done = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True, check=False)
            if done.returncode != 0:
                raise CourseError(f"{shown} exited with code {done.returncode}",
                                  details=done.stderr.splitlines())


def summaries(out):
    """Run summaries (JSON with "lab" and "seconds") in OUT/<lab>/*.json."""
    found = []
    for path in sorted(out.glob("lab[0-9][0-9]_*/*.json")):
        try:
            data = json.loads(path.read_text())
        except (OSError, ValueError):
            continue
        if isinstance(data, dict) and "lab" in data and "seconds" in data:
            found.append(data)
    return found


def cell(value, fmt="{:.3g}"):
    """A table cell: numbers formatted, a missing value as `-`."""
    if value is None:
        return "-"
    return fmt.format(value) if isinstance(value, (int, float)) else str(value)


def outcome(summary):
    """What a run reported about itself: its "outcome", or "diverged", or nothing."""
    if "outcome" in summary:
        return str(summary["outcome"])
    return "diverged" if summary.get("diverged") else ""


def print_summary_table(out):
    rows = [[cell(s["lab"]), cell(s.get("scene")), cell(s.get("method")),
             cell(s.get("iterations"), "{}"), cell(s.get("max_strain_error")),
             cell(s["seconds"]), outcome(s)]
            for s in summaries(out)]
    if not rows:
        return
    header = ["lab", "scene", "method", "iterations", "max_strain_error", "seconds", "outcome"]
    widths = [max(len(row[i]) for row in [header, *rows]) for i in range(len(header))]
    print()
    for row in [header, *rows]:
        print("  ".join(cell.ljust(width) for cell, width in zip(row, widths)).rstrip())


def cmd_demo(argv):
    parser = argparse.ArgumentParser(prog="course demo")
    parser.add_argument("--out", default="out", help="output directory (default out/)")
    out = under_root(parser.parse_args(argv).out)
    run_demos(out)
    outcomes = run_plots(out)
    print_summary_table(out)
    print(f"\noutputs: {show(out)}/")
    return 1 if plots_failed(outcomes) else 0


# ---------------------------------------------------------------- plots

def plot_scripts():
    """plots/*.py, sorted; `_name.py` files are helpers, not scripts."""
    return sorted(p for p in (ROOT / "plots").glob("*.py") if not p.name.startswith("_"))


def run_plots(directory, echo=True, names=None):
    """Run every plot script (or those named) on DIRECTORY; return {script: (ok|skipped|failed, error lines)}."""
    env = dict(os.environ, MPLBACKEND="Agg")
    outcomes = {}
    for script in plot_scripts():
        if names is not None and script.name not in names:
            continue
        done = subprocess.run([sys.executable, str(script.relative_to(ROOT)), str(directory)],
                              cwd=ROOT, env=env, capture_output=True, text=True, check=False)
        if done.returncode == 0:
            outcome = ("ok", [])
        elif done.returncode == PLOT_SKIPPED:
            # The script's one line: the missing file and the command that makes it.
            said = [line for line in (done.stderr + done.stdout).splitlines() if line.strip()]
            outcome = ("skipped", said[:1])
        else:
            error = [f"exit code {done.returncode}", *done.stderr.splitlines()[-PLOT_ERROR_LINES:]]
            outcome = ("failed", error)
        outcomes[script.name] = outcome
        if echo:
            print(f"  plots/{script.name}: {outcome[0]}", flush=True)
            for line in outcome[1]:
                print(f"    {line}")
    return outcomes


def plots_failed(outcomes):
    return any(status == "failed" for status, _ in outcomes.values())


def cmd_plots(argv):
    parser = argparse.ArgumentParser(prog="course plots")
    parser.add_argument("dir", nargs="?", default="out", help="directory with CSV/JSON (default out/)")
    directory = under_root(parser.parse_args(argv).dir)
    if not directory.is_dir():
        raise CourseError(f"{show(directory)} is not a directory (make it with ./course demo)", code=2)
    if not plot_scripts():
        print("no plot scripts in plots/ yet")
    return 1 if plots_failed(run_plots(directory)) else 0


# ---------------------------------------------------------------- grade

class Grader:
    """Builds and grades labs one at a time, remembering each result, so a lab
    whose tests link an earlier lab's student code can say how that lab scores."""

    def __init__(self, solutions=False, select=None, log=sys.stdout, sanitize=True, info=True, hidden=False):
        self.solutions = solutions
        self.hidden = hidden  # also the [hidden] cases (the honesty checks)
        self.select = select
        self.log = log
        self.sanitize = sanitize
        self.info = info
        self.results = {}

    def grade(self, lab, select=None, info=True):
        """A LabResult for `lab`, with .build_errors, .warnings, .info, .crashes."""
        key = (lab, select is not None)
        if key in self.results:
            result = self.results[key]
            if info and self.info and result.info is None and manifest()[lab].get("info"):
                result.info = self.run_info(lab)
            return result
        result = grade.LabResult(lab)
        result.build_errors, result.warnings, result.info, result.crashes = [], [], None, {}
        result.max_known = None
        self.results[key] = result
        if lab not in manifest():
            result.errors.append(f"{lab} is not added in CMakeLists.txt (add_lab)")
            return result
        if self.solutions and not manifest()[lab]["reference"]:
            result.errors.append(f"{lab} has no reference in solutions/{lab}/")
            return result
        try:
            output = build_targets(lab_targets(lab, self.solutions), log=self.log, label=lab)
        except BuildFailure as failure:
            result.build_errors = failure.lines
            result.max_known = grade.source_points(ROOT / "tests" / lab, grade.lab_tag(lab))
            return result
        if not self.solutions:
            result.warnings = student_warnings(lab, output)
        suffix = "_tests_solution" if self.solutions else "_tests"
        graded = grade.grade_lab(lab, BIN / (lab + suffix), ROOT, select, hidden=self.hidden)
        result.cases, result.errors = graded.cases, result.errors + graded.errors
        if self.sanitize and not self.solutions:
            for case in [c for c in result.cases if c.signal][:2]:
                result.crashes[case.name] = sanitizer_rerun(lab, case, log=self.log)
                case.details = [*result.crashes[case.name], *case.details]
        if info and self.info and manifest()[lab].get("info"):
            result.info = self.run_info(lab)
        return result

    def run_info(self, lab):
        """The info program's line for the student's code (and the reference's)."""
        programs = [("the reference", f"{lab}_info_solution")] if self.solutions else [
            ("your code", f"{lab}_info")]
        if not self.solutions and manifest()[lab]["reference"]:
            programs.append(("the reference", f"{lab}_info_solution"))
        lines = []
        for who, name in programs:
            try:
                done = subprocess.run([str(BIN / name)], cwd=ROOT, capture_output=True, text=True,
                                      timeout=30, check=False)
                text = (done.stdout.strip().splitlines() or [f"exit code {done.returncode}"])[0]
            except (OSError, subprocess.TimeoutExpired) as error:
                text = f"not measured ({error})"
            lines.append(f"{who}: {text}")
        return lines

    def dependency_notes(self, lab):
        """One line per earlier lab whose STUDENT code `lab`'s tests link."""
        if self.solutions:
            return []
        notes = []
        links = manifest().get(lab, {}).get("links", {})
        for dep in sorted(d for d, kind in links.items() if kind == "student"):
            this, that = number_of(lab), number_of(dep)
            result = self.grade(dep, info=False)
            if result.build_errors:
                notes.append(f"lab {this} links your lab {that} code, which does not compile: fix it first")
                continue
            fmt = grade.fmt_points
            line = f"lab {this} links your lab {that} code: lab {that} scores {fmt(result.score)}/{fmt(result.max_score)}"
            if result.score < result.max_score or result.errors or not result.cases:
                line += " — fix it first"
            notes.append(line)
        return notes


def number_of(lab):
    return grade.lab_id(lab)[3:]


def print_grades(results, notes, verbose=False):
    """Per-lab table; failed cases with the reason and their context; build
    errors, warnings, notes on earlier labs; `Score: X/Y`."""
    fmt = grade.fmt_points
    rows = [["lab", "cases", "points"]]
    for r in results:
        if r.build_errors:
            rows.append([r.lab, "-", f"0/{fmt(r.max_known)}  does not compile"])
        else:
            rows.append([r.lab, f"{len(r.passed)}/{len(r.cases)}", f"{fmt(r.score)}/{fmt(r.max_score)}"])
    widths = [max(len(row[i]) for row in rows) for i in range(2)]
    print()
    for row in rows:
        print(f"{row[0]:<{widths[0]}}  {row[1]:>{widths[1]}}  {row[2]}")
    for r in results:
        tag = grade.lab_id(r.lab)
        if r.build_errors:
            print(f"  BUILD {tag}: the compiler's first errors:")
            for line in r.build_errors:
                print(f"    | {line}")
        for case in r.cases:
            if case.passed:
                if verbose:
                    print(f'  pass {tag} "{case.name}" ({fmt(case.points)} pts)')
                continue
            print(f'  FAIL {tag} "{case.name}" ({fmt(case.points)} pts)')
            print(f"       {grade.clip(case.reason, grade.TERMINAL_CAP)}")
            crash = r.crashes.get(case.name, [])
            for line in crash:
                print(f"       {grade.clip(line, grade.TERMINAL_CAP)}")
            context = grade.context_line(grade.CaseResult(case.name, 0, False, "", case.details[len(crash):]))
            if context:
                print(f"       {grade.clip(context, grade.TERMINAL_CAP)}")
        for error in r.errors:
            print(f"  ERROR {error}")
        if r.warnings:
            print(f"  {len(r.warnings)} compiler warning{'s' if len(r.warnings) != 1 else ''} in your "
                  f"{tag} code{' (first ' + str(WARNING_LINES) + ')' if len(r.warnings) > WARNING_LINES else ''}:")
            for line in r.warnings[:WARNING_LINES]:
                print(f"    {grade.clip(line, grade.TERMINAL_CAP)}")
        for note in notes.get(r.lab, []):
            print(f"  {note}")
        if r.info:
            print(f"  {tag} information, not graded:")
            for line in r.info:
                print(f"    {line}")
    score = sum(r.score for r in results)
    max_score = sum(r.max_known if r.build_errors else r.max_score for r in results)
    print(f"Score: {fmt(score)}/{fmt(max_score)}")


def write_results(path, results):
    """results.json, with a lab that did not compile as one failed entry."""
    for r in results:
        if r.build_errors:
            r.errors = [*r.errors, "does not compile:\n" + "\n".join(r.build_errors)]
    grade.write_gradescope(path, results)


def cmd_grade(argv):
    parser = argparse.ArgumentParser(prog="course grade")
    parser.add_argument("labs", nargs="*", metavar="labNN", help="labs to grade (default: all)")
    parser.add_argument("--solutions", action="store_true", help="grade the reference code")
    parser.add_argument("-t", "--test", metavar="PATTERN",
                        help="only the cases whose name contains PATTERN (or matches it, with * wildcards)")
    parser.add_argument("-v", "--verbose", action="store_true", help="also list the passing cases")
    parser.add_argument("--output", default=str(BUILD / "grade" / "results.json"),
                        help="Gradescope JSON (default build/grade/results.json)")
    args = parser.parse_args(argv)
    labs = list(dict.fromkeys(resolve_lab(token) for token in args.labs)) or lab_dirs()
    configure()
    if args.solutions:
        missing = [lab for lab in labs if not manifest().get(lab, {}).get("reference")]
        if missing:
            raise CourseError(f"--solutions: no reference in solutions/ for {', '.join(missing)}", code=2)
    select = grade.case_filter(args.test)
    grader = Grader(solutions=args.solutions, info=select is None)
    results = [grader.grade(lab, select) for lab in labs]
    if select is not None:
        print(f"(only the cases matching '{args.test}': "
              f"{sum(len(r.cases) for r in results)} of them)")
    notes = {r.lab: grader.dependency_notes(r.lab) for r in results}
    print_grades(results, notes, verbose=args.verbose)
    output = under_root(args.output)
    write_results(output, results)
    print(f"results: {show(output)}")
    return 1 if any(r.errors or r.build_errors for r in results) else 0


# ---------------------------------------------------------------- release
#
# A student release for the week of lab NN: every file of the course (git's
# tracked and untracked-but-not-ignored files, or a plain copy), with the stubs
# in labs/ and, in solutions/, only the reference code of the labs before NN
# (released after their deadlines). The build links those references into
# later labs' tests (cmake/AddLab.cmake), so a mistake in lab 01 is charged in
# lab 01 only. release_files() is the one place that decides what ships.

RELEASE_MARKER = "release.json"
HIDDEN_TESTS = re.compile(r"^tests/[^/]+/hidden_[^/]*\.cpp$")  # never in a release (tools/autograder.py)
SKIPPED_DIRS = {".git", "build", "out", "__pycache__"}


def is_release():
    """True in a student release (the marker written by ./course release)."""
    return (ROOT / RELEASE_MARKER).is_file()


def course_files():
    """Paths (relative to ROOT) of every file of the course."""
    if (ROOT / ".git").exists() and shutil.which("git"):
        done = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-z", "--cached", "--others",
                               "--exclude-standard"], capture_output=True, text=True, check=False)
        if done.returncode == 0:
            return sorted(f for f in set(done.stdout.split("\0")) if f and (ROOT / f).is_file())
    skipped = SKIPPED_DIRS | {BUILD.name}
    files = []
    for path in ROOT.rglob("*"):
        relative = path.relative_to(ROOT)
        if path.is_file() and not skipped.intersection(relative.parts) and path.suffix != ".pyc":
            files.append(str(relative))
    return sorted(files)


def release_files(lab, keep=None):
    """(files, past labs) of the release for `lab`: everything but the solutions
    of `lab` and later labs; `keep(path)` decides the rest (default: all but the
    hidden tests, tests/*/hidden_*.cpp)."""
    keep = keep or (lambda path: not HIDDEN_TESTS.match(path))
    labs = lab_dirs()
    past = labs[:labs.index(lab)]
    missing = [p for p in past if not (ROOT / "solutions" / p).is_dir()]
    if missing:
        raise CourseError(f"no reference in solutions/ for {', '.join(missing)}: cannot release them", code=2)
    files = []
    for path in course_files():
        parts = Path(path).parts
        if parts[0] == "solutions" and len(parts) > 1 and parts[1] not in past:
            continue
        if path == RELEASE_MARKER or not keep(path):
            continue
        files.append(path)
    return files, past


def write_release(lab, dest, keep=None):
    """Write the release for `lab` into DEST (new or empty); return its file count."""
    if is_release():
        raise CourseError("this is a student release already; release from the instructor's tree", code=2)
    if dest.exists() and any(dest.iterdir()):
        raise CourseError(f"{dest} is not empty", code=2)
    files, past = release_files(lab, keep)
    for path in files:
        target = dest / path
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / path, target)
    marker = {"release": lab, "references": past,
              "note": "stubs for every lab; solutions/ holds the reference code of the labs before "
                      f"{grade.lab_id(lab)} (docs/DESIGN.md §4)"}
    (dest / RELEASE_MARKER).write_text(json.dumps(marker, indent=2) + "\n")
    return len(files) + 1


def cmd_release(argv):
    parser = argparse.ArgumentParser(prog="course release")
    parser.add_argument("lab", metavar="labNN", help="the lab of the week: its and later labs' solutions stay out")
    parser.add_argument("dest", metavar="DIR", help="where to write the student tree (new or empty)")
    args = parser.parse_args(argv)
    lab = resolve_lab(args.lab)
    dest = Path(args.dest).resolve()
    count = write_release(lab, dest)
    past = release_files(lab)[1]
    print(f"{dest}: {count} files; stubs for {len(lab_dirs())} labs; reference code for "
          f"{', '.join(grade.lab_id(p) for p in past) or 'no lab'}")
    return 0


# ---------------------------------------------------------------- test

class Checks:
    """Counts and prints pass/fail checks."""

    def __init__(self):
        self.passed = 0
        self.failed = 0

    def record(self, ok, name, details=()):
        if ok:
            self.passed += 1
        else:
            self.failed += 1
        print(f"{'ok  ' if ok else 'FAIL'}  {name}", flush=True)
        for line in details:
            print(f"        {line}")

    def finish(self):
        """Print `N passed, M failed`; return the exit code."""
        print(f"{self.passed} passed, {self.failed} failed")
        return 1 if self.failed else 0


def build_labs(checks, labs):
    """Build each lab's targets on its own; return the labs that built."""
    built = []
    for lab in labs:
        entry = manifest().get(lab)
        if entry is None:
            checks.record(False, f"{lab}: not added in CMakeLists.txt (add_lab)")
            continue
        targets = [lab, *lab_targets(lab)]
        if entry["reference"]:
            targets += [f"{lab}_solution", *lab_targets(lab, solutions=True)]
        try:
            build_targets(list(dict.fromkeys(targets)), log=None)
        except BuildFailure as failure:
            checks.record(False, f"{lab} does not build", failure.lines)
            continue
        built.append(lab)
    return built


def check_ctest(checks):
    try:
        build_targets(["common_tests"], log=None)
    except BuildFailure as failure:
        checks.record(False, "common_tests does not build", failure.lines)
        return
    done = subprocess.run(["ctest", "--test-dir", str(BUILD), "-L", "unit", "--output-on-failure"],
                          cwd=ROOT, capture_output=True, text=True, check=False)
    ok = done.returncode == 0
    lines = [line for line in done.stdout.splitlines() if "tests passed" in line]
    details = [] if ok else (done.stdout + done.stderr).splitlines()
    checks.record(ok, f"ctest -L unit: {lines[-1] if lines else 'no tests found'}", details)


def check_solutions(checks, labs):
    grader = Grader(solutions=True, log=None, info=False, hidden=True)
    results = [grader.grade(lab) for lab in labs]
    write_results(BUILD / "grade" / "solutions" / "results.json", results)
    for r in results:
        fmt = grade.fmt_points
        details = [f'"{c.name}": {c.reason}' for c in r.failed] + r.errors
        ok = not details and bool(r.cases) and r.score == r.max_score
        checks.record(ok, f"{r.lab} solutions: {fmt(r.score)}/{fmt(r.max_score)}", details)


def check_stubs(checks, labs):
    grader = Grader(log=None, sanitize=False, info=False, hidden=True)
    results = [grader.grade(lab) for lab in labs]
    write_results(BUILD / "grade" / "stubs" / "results.json", results)
    for r in results:
        details = [f'passes on the stubs: "{c.name}"' for c in r.passed] + r.errors
        if not r.cases:
            summary = "no graded cases"
        elif r.passed:
            summary = f"{len(r.passed)} of {len(r.cases)} graded cases pass"
        else:
            summary = f"all {len(r.cases)} graded cases fail"
        checks.record(not details and bool(r.cases), f"{r.lab} stubs: {summary}", details)


def report_student_score(labs):
    grader = Grader(log=None)
    results = [grader.grade(lab) for lab in labs]
    write_results(BUILD / "grade" / "results.json", results)
    fmt = grade.fmt_points
    for r in results:
        if r.build_errors:
            print(f"      {r.lab} (your code): does not compile (./course grade {grade.lab_id(r.lab)})")
            continue
        print(f"      {r.lab} (your code): {fmt(r.score)}/{fmt(r.max_score)}")
        for error in r.errors:
            print(f"        {error}")
        for note in grader.dependency_notes(r.lab):
            print(f"        {note}")


def check_demo(checks, out, labs, student_fallback=True):
    shutil.rmtree(out, ignore_errors=True)
    try:
        run_demos(out, echo=False, labs=labs, student_fallback=student_fallback)
    except CourseError as error:
        checks.record(False, f"demo: {error}", error.details)
        return
    checks.record(True, f"demo -> {show(out)}/")


def reject_lines(lab):
    """labs/LAB/rejects.txt: (arguments, expected text) per line `ARGS -> TEXT`."""
    path = ROOT / "labs" / lab / "rejects.txt"
    if not path.is_file():
        return []
    found = []
    for number, line in enumerate(path.read_text().splitlines(), 1):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        args, arrow, expected = line.rpartition(" -> ")
        if not arrow or not args.strip() or not expected.strip():
            raise CourseError(f"{show(path)}:{number}: expected `ARGS -> TEXT`")
        found.append((shlex.split(args), expected.strip()))
    return found


def refusal_problem(program, args, expected):
    """Run PROGRAM on one bad input in a scratch folder; what is wrong with how
    it refused (None: exit code 2, one stderr line containing EXPECTED, nothing
    written). A --scene argument that starts with `{` is JSON, written to
    scratch/bad.json first; `{tmp}` is the scratch folder."""
    with tempfile.TemporaryDirectory(prefix="cl-reject-") as scratch:
        scratch = Path(scratch)
        argv = [arg.replace("{tmp}", str(scratch)) for arg in args]
        for i in range(1, len(argv)):
            if argv[i - 1] == "--scene" and argv[i].startswith("{"):
                (scratch / "bad.json").write_text(argv[i])
                argv[i] = str(scratch / "bad.json")
        before = sorted(scratch.rglob("*"))
        try:
            done = subprocess.run([str(program), *argv], cwd=scratch, capture_output=True, text=True,
                                  timeout=60, check=False)
        except subprocess.TimeoutExpired:
            return "ran past 60 s instead of refusing"
        lines = done.stderr.splitlines()
        if done.returncode != 2:
            return f"exit code {done.returncode}, not 2; stderr: {' | '.join(lines[-3:]) or '(empty)'}"
        if len(lines) != 1:
            return f"{len(lines)} stderr lines, not 1: {' | '.join(lines[:3])}"
        if expected not in lines[0]:
            return f"the line does not say '{expected}': {lines[0]}"
        written = [str(p.relative_to(scratch)) for p in sorted(scratch.rglob("*")) if p not in before]
        if written:
            return f"left output behind: {', '.join(written[:3])}"
    return None


def check_rejects(checks, labs):
    """Every line of labs/*/rejects.txt: the lab's executable refuses it (docs/DESIGN.md §3)."""
    entries = manifest()
    for lab in labs:
        try:
            cases = reject_lines(lab)
        except CourseError as error:
            checks.record(False, str(error))
            continue
        if not cases:
            continue
        name = lab + ("_solution" if entries[lab]["reference"] else "")
        program = BIN / name
        problems = []
        for args, expected in cases:
            problem = refusal_problem(program, args, expected)
            if problem:
                problems.append(f"{shlex.join(args)}: {problem}")
        checks.record(not problems, f"{lab} refuses {len(cases) - len(problems)}/{len(cases)} bad inputs "
                      f"(labs/{lab}/rejects.txt: exit 2, one line, nothing written)", problems)


def sub_course(tree, *args):
    """Run tree's own ./course (its tools/course.py) with its own build dir."""
    env = dict(os.environ, CL_BUILD_DIR=str(tree / "build"))
    done = subprocess.run([sys.executable, str(tree / "tools" / "course.py"), *args], cwd=tree, env=env,
                          capture_output=True, text=True, check=False)
    return done.returncode, (done.stdout + done.stderr).splitlines()


def lab_scores(results_json):
    """{labNN: [score, max]} from a results.json."""
    scores = {}
    try:
        data = json.loads(results_json.read_text())
    except (OSError, ValueError):
        return scores
    for test in data["tests"]:
        tag = test["name"].split(":", 1)[0]
        entry = scores.setdefault(tag, [0, 0])
        entry[0] += test["score"]
        entry[1] += test["max_score"]
    return scores


def check_student_loop(checks):
    """Issue 13's promises, proved in a student release of lab 03 (one temp tree,
    one build): a wrong lab 01 is charged in lab 01 only; a lab that does not
    compile blocks no other; a crash is located by the sanitizer build."""
    ids = {grade.lab_id(lab): lab for lab in lab_dirs()}
    if not all(k in ids for k in ("lab01", "lab03", "lab04")):
        return
    lab1, lab3, lab4 = ids["lab01"], ids["lab03"], ids["lab04"]
    spring = ROOT / "solutions" / lab1 / "single_spring.cpp"
    reference = spring.read_text()
    sign_error = reference.replace("correction.dx_i = -(", "correction.dx_i = (")
    bug = "  return (-constraint / denominator) * (gradients * inv_mass.asDiagonal());\n"
    crash = reference.replace(bug, "  Eigen::Matrix3Xd corrections;  // never sized: the bug\n"
                              "  for (Eigen::Index k = 0; k < gradients.cols(); ++k)\n"
                              "    corrections.col(k) = (-constraint * inv_mass[k] / denominator) * gradients.col(k);\n"
                              "  return corrections;\n")
    if sign_error == reference or crash == reference:
        checks.record(False, "student loop: cannot plant the bugs in solutions/lab01 (code changed?)")
        return
    start = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="cl-release-") as work:
        tree = Path(work) / "release"
        write_release(lab3, tree)
        shipped = sorted(p.name for p in (tree / "solutions").iterdir())
        checks.record(shipped == [lab1, ids["lab02"]] and not (tree / "solutions" / lab3).exists(),
                      f"release lab03: solutions/ holds {', '.join(shipped)} only")

        # 1. A sign error in lab 01 costs lab 01 points, lab 03 (reference code) none.
        (tree / "labs" / lab1 / "single_spring.cpp").write_text(sign_error)
        for source in (ROOT / "solutions" / lab3).glob("*.cpp"):
            shutil.copy2(source, tree / "labs" / lab3 / source.name)
        code, lines = sub_course(tree, "grade", "lab01", "lab03")
        scores = lab_scores(tree / "build" / "grade" / "results.json")
        s1, s3 = scores.get("lab01", [0, 0]), scores.get("lab03", [0, 1])
        checks.record(s3[1] > 0 and s3[0] == s3[1] and s1[0] < s1[1],
                      f"release lab03, lab 01 with a sign error: lab01 {s1[0]:g}/{s1[1]:g}, "
                      f"lab03 {s3[0]:g}/{s3[1]:g} (full: charged once)", [] if s3[0] == s3[1] else lines)

        # 2. Lab 04 does not compile: lab 01 still grades, lab 04 shows the error.
        pbd = tree / "labs" / lab4 / "pbd.cpp"
        pbd.write_text(pbd.read_text() + "\nint this_line_does_not_compile = ;\n")
        code, lines = sub_course(tree, "grade", "lab01", "lab04")
        scores = lab_scores(tree / "build" / "grade" / "results.json")
        text = "\n".join(lines)
        ok = (scores.get("lab01") == s1 and "BUILD lab04" in text and "pbd.cpp:" in text
              and "lab 04 links your lab 03 code: lab 03 scores" in text)
        checks.record(ok, "release lab03, lab 04 does not compile: lab 01 still grades "
                      f"({scores.get('lab01', [0, 0])[0]:g}/{s1[1]:g}), lab 04 shows the compiler's error",
                      [] if ok else lines)

        # 3. A crash in lab 01 is rerun under the sanitizers, which name the line.
        (tree / "labs" / lab1 / "single_spring.cpp").write_text(crash)
        line = next(i for i, l in enumerate(crash.splitlines(), 1) if "corrections.col(k) =" in l)
        where = f"labs/{lab1}/single_spring.cpp:{line}"
        code, lines = sub_course(tree, "grade", "lab01")
        text = "\n".join(lines)
        ok = "crashed (signal" in text and where in text
        checks.record(ok, f"release lab03, lab 01 writes past an unsized matrix: grade names {where}",
                      [] if ok else lines)
    checks.record(True, f"student loop checks: {time.monotonic() - start:.0f} s")


def cmd_test(argv):
    argparse.ArgumentParser(prog="course test").parse_args(argv)
    checks = Checks()
    try:
        configure()
    except CourseError as error:
        checks.record(False, str(error), error.details)
        return checks.finish()
    labs = build_labs(checks, lab_dirs())
    check_ctest(checks)
    out = BUILD / "test-demo"
    if is_release():
        print("a student release: grading your code (a score, not a check)")
        report_student_score(labs)
        with_reference = [lab for lab in labs if manifest()[lab]["reference"]]
        check_demo(checks, out, with_reference, student_fallback=False)
        check_rejects(checks, with_reference)
    else:
        without = [lab for lab in labs if not manifest()[lab]["reference"]]
        for lab in without:
            checks.record(False, f"{lab}: no reference in solutions/{lab}/ (the honesty check needs one)")
        labs = [lab for lab in labs if lab not in without]
        check_solutions(checks, labs)
        check_stubs(checks, labs)
        check_demo(checks, out, labs)
        check_rejects(checks, labs)
        check_measurements(checks, out)
        check_fuzz(checks)
        check_sanitize(checks)
    for script, (status, error) in run_plots(out, echo=False).items():
        checks.record(status in ("ok", "skipped") if is_release() else status == "ok",
                      f"plots/{script} on {show(out)}: {status}", error)
    if not is_release():
        check_student_loop(checks)
        import autograder  # here: it imports this module
        autograder.check_autograder(checks)
    return checks.finish()


# ---------------------------------------------------------------- run, bench

def cmd_run(argv):
    if not argv or argv[0].startswith("-"):
        raise CourseError("usage: ./course run labNN [ARGS]  (labNN_solution: the reference)", code=2)
    token, solution = argv[0], argv[0].endswith("_solution")
    lab = resolve_lab(token.removesuffix("_solution"))
    configure(log=sys.stderr)
    if solution and not manifest().get(lab, {}).get("reference"):
        raise CourseError(f"no reference for {lab} here (solutions/{lab}/)", code=2)
    name = lab + ("_solution" if solution else "")
    try:
        build_targets([name], log=sys.stderr)
    except BuildFailure as failure:
        raise CourseError(f"{name} does not build", details=failure.lines) from None
    program = executable(name)
    sys.stdout.flush()
    os.execv(program, [str(program), *argv[1:]])


MEASUREMENT_PLOTS = {"trade": ("bench_pareto.py", "bench_scaling.py"), "extremes": ("bench_extremes.py",)}


def run_measurement(program, args, out, echo=True):
    """Build and run bench/PROGRAM (trade or extremes) into OUT/bench.
    Return (exit code, output lines); with echo the output goes to the terminal as it comes."""
    build_targets([program], log=sys.stdout if echo else None)
    path = executable(program)
    command = [str(path), "--out", str(out / "bench"), *args]
    if echo:
        print("  " + shlex.join([path.name, *command[1:]]), flush=True)
    done = subprocess.run(command, cwd=ROOT, capture_output=not echo, text=True, check=False)
    return done.returncode, [] if echo else (done.stdout + done.stderr).splitlines()


def measurement_command(program, argv):
    """./course bench | extremes [--quick] [--out DIR]: the program, then the figures."""
    parser = argparse.ArgumentParser(prog=f"course {'bench' if program == 'trade' else program}")
    parser.add_argument("--quick", action="store_true", help="the CI size (minutes, not tens of them)")
    parser.add_argument("--out", default="out", help="output directory (default out/; CSV in OUT/bench)")
    if program == "trade":
        parser.add_argument("--micro", nargs=argparse.REMAINDER,
                            help="also run the Google Benchmark programs (bench_*), ARGS pass through")
    args = parser.parse_args(argv)
    configure()
    out = under_root(args.out)
    code, _ = run_measurement(program, ["--quick"] if args.quick else [], out)
    if plots_failed(run_plots(out, names=MEASUREMENT_PLOTS[program])):
        code = max(code, 1)
    if program == "trade" and args.micro is not None:
        code = max(code, run_micro(args.micro))
    return code


def micro_targets():
    """The Google Benchmark programs: bench/bench_NAME.cpp is the target bench_NAME,
    where this build defines it (bench/CMakeLists.txt adds those whose references exist)."""
    names = sorted(path.stem for path in (ROOT / "bench").glob("bench_*.cpp"))
    return [name for name in names if (BUILD / "bench" / "CMakeFiles" / f"{name}.dir").is_dir()]


def run_micro(argv):
    targets = micro_targets()
    if not targets:
        raise CourseError("no Google Benchmark program in this build (bench/bench_*.cpp need "
                          "libbenchmark-dev and the labs' references)")
    build_targets(targets)
    failed = []
    for name in targets:
        print(f"== {name}", flush=True)
        if subprocess.run([str(executable(name)), *argv], cwd=ROOT, check=False).returncode != 0:
            failed.append(name)
    if failed:
        raise CourseError(f"failed: {' '.join(failed)}")
    return 0


def cmd_bench(argv):
    return measurement_command("trade", argv)


def cmd_extremes(argv):
    return measurement_command("extremes", argv)


def check_measurements(checks, out):
    """CI: the quick trade and extremes runs (extremes fails on any silent NaN)."""
    for program in ("trade", "extremes"):
        try:
            code, lines = run_measurement(program, ["--quick"], out, echo=False)
        except (CourseError, BuildFailure) as error:
            checks.record(False, f"{program} --quick: {error}")
            continue
        checks.record(code == 0, f"{program} --quick: {lines[-1] if lines else 'no output'}",
                      [] if code == 0 else lines[-20:])


REGRESSIONS = ROOT / "tests" / "common" / "scene_regressions"


def run_fuzz(seconds, log=sys.stdout):
    """Build fuzz/ with clang++ into BUILD/fuzz and fuzz the scene loader for SECONDS,
    starting from every shipped scene and saved regression input, with the scene
    format's dictionary. A crashing input is copied into tests/common/scene_regressions/.
    Return (ok, last lines of libFuzzer's output, the copied inputs)."""
    fuzz_build = BUILD / "fuzz"
    if shutil.which("clang++") is None:
        raise CourseError("clang++ not found (apt-get install clang libclang-rt-14-dev)", code=2)
    if not (fuzz_build / "CMakeCache.txt").is_file():
        quiet(["cmake", "-S", str(ROOT / "fuzz"), "-B", str(fuzz_build), "-DCMAKE_CXX_COMPILER=clang++",
               "-DCMAKE_BUILD_TYPE=RelWithDebInfo"], "configure fuzz/")
    build_targets(["fuzz_scene"], build_dir=fuzz_build, log=log)
    corpus = fuzz_build / "corpus"
    corpus.mkdir(exist_ok=True)
    seeds = [*ROOT.glob("labs/*/scenes/*.json"), *(p for p in REGRESSIONS.glob("*") if p.name != "README.md")]
    for seed in seeds:
        shutil.copy(seed, corpus / f"seed-{seed.name}")
    artifacts = fuzz_build / "crashes"
    shutil.rmtree(artifacts, ignore_errors=True)
    artifacts.mkdir()
    done = subprocess.run([str(fuzz_build / "fuzz_scene"), f"-max_total_time={seconds}", "-rss_limit_mb=2048",
                           "-max_len=4096", f"-dict={ROOT / 'fuzz' / 'scene.dict'}",
                           f"-artifact_prefix={artifacts}/", str(corpus)],
                          cwd=fuzz_build, capture_output=True, text=True, check=False)
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    kept = []
    for artifact in sorted(artifacts.iterdir()):
        target = REGRESSIONS / artifact.name
        shutil.copy(artifact, target)
        kept.append(target)
    return done.returncode == 0, lines[-12:], kept


def cmd_fuzz(argv):
    parser = argparse.ArgumentParser(prog="course fuzz")
    parser.add_argument("seconds", nargs="?", type=int, default=60, help="how long to fuzz (default 60)")
    args = parser.parse_args(argv)
    ok, lines, kept = run_fuzz(args.seconds)
    for line in lines:
        print(line)
    if ok:
        print("fuzz: no crash")
        return 0
    for path in kept:
        print(f"fuzz: a crashing input, kept as a regression test: {show(path)}")
    print("fuzz: fix the loader until ./course test passes, then commit the input with the fix")
    return 1


def check_fuzz(checks, seconds=60):
    try:
        ok, lines, kept = run_fuzz(seconds, log=None)
    except (CourseError, BuildFailure) as error:
        checks.record(False, f"fuzz the scene loader: {error}")
        return
    runs = next((line for line in reversed(lines) if line.startswith("Done ")), "")
    details = [] if ok else [*lines, *(f"kept as a regression test: {show(path)}" for path in kept)]
    checks.record(ok, f"fuzz the scene loader for {seconds} s: {runs or 'no summary'}", details)


SANITIZE_BUILD = BUILD / "asan"


def sanitize_targets():
    """The whole test suite: common_tests and every lab's graded tests on its reference."""
    labs = [lab for lab, entry in manifest().items() if entry["reference"]]
    return ["common_tests", *(f"{lab}_tests_solution" for lab in labs)]


def run_sanitized(log=sys.stdout):
    """Build the test suite with -fsanitize=address,undefined (CMakeLists.txt: CL_SANITIZE)
    into BUILD/asan and run every test program there, every case (hidden ones too).
    Return [(program, ok, summary line, report lines)]."""
    configure(log=log)  # labs.json says which labs have a reference
    if not (SANITIZE_BUILD / "CMakeCache.txt").is_file():
        quiet(["cmake", "-S", str(ROOT), "-B", str(SANITIZE_BUILD), "-DCL_SANITIZE=ON",
               "-DCMAKE_BUILD_TYPE=RelWithDebInfo", "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1"],
              "configure the sanitizer build")
    targets = sanitize_targets()
    build_targets(targets, build_dir=SANITIZE_BUILD, log=log, label="the test suite (-fsanitize=address,undefined)")
    env = sanitizer_env(leaks=True)
    results = []
    for name in targets:
        start = time.monotonic()
        with tempfile.TemporaryDirectory(prefix="cl-asan-") as work:
            done = subprocess.run([str(SANITIZE_BUILD / "bin" / name)], cwd=work, env=env, capture_output=True,
                                  text=True, check=False)
        output = done.stdout + done.stderr
        report = grade.sanitizer_report(output, ROOT)
        ok = done.returncode == 0 and not report
        lines = output.splitlines()
        summary = next((line for line in reversed(lines) if "test cases" in line or "All tests passed" in line),
                       f"exit code {done.returncode}")
        results.append((name, ok, f"{summary.strip()} ({time.monotonic() - start:.1f} s)",
                        report or ([] if ok else lines[-20:])))
    return results


def cmd_sanitize(argv):
    argparse.ArgumentParser(prog="course sanitize").parse_args(argv)
    failed = 0
    for name, ok, summary, report in run_sanitized():
        print(f"{'ok  ' if ok else 'FAIL'}  {name}: {summary}")
        for line in report:
            print(f"        {line}")
        failed += not ok
    print("sanitize: clean" if not failed else f"sanitize: {failed} program(s) with findings or failures")
    return 1 if failed else 0


def check_sanitize(checks):
    """CI: the whole test suite under ASan and UBSan, clean."""
    try:
        results = run_sanitized(log=None)
    except (CourseError, BuildFailure) as error:
        checks.record(False, f"sanitizer build: {error}", getattr(error, "lines", getattr(error, "details", [])))
        return
    for name, ok, summary, report in results:
        checks.record(ok, f"{name} under ASan+UBSan: {summary}", report)


def cmd_autograder(argv):
    import autograder  # here: it imports this module
    return autograder.cmd_autograder(argv)


# ---------------------------------------------------------------- main

COMMANDS = {"demo": cmd_demo, "test": cmd_test, "grade": cmd_grade, "run": cmd_run,
            "plots": cmd_plots, "bench": cmd_bench, "extremes": cmd_extremes, "fuzz": cmd_fuzz, "sanitize": cmd_sanitize,
            "release": cmd_release, "autograder": cmd_autograder}


def main(argv):
    if not argv or argv[0] in ("help", "-h", "--help"):
        print(USAGE)
        return 0
    command = COMMANDS.get(argv[0])
    if command is None:
        print(f"course: unknown command '{argv[0]}' (try ./course help)", file=sys.stderr)
        return 2
    try:
        return command(argv[1:])
    except CourseError as error:
        for line in error.details:
            print(line, file=sys.stderr)
        print(f"course: {error}", file=sys.stderr)
        return error.code
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
