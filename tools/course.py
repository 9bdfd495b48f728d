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
import sys
import time
from pathlib import Path

import grade

ROOT = Path(__file__).resolve().parent.parent
BUILD = ROOT / os.environ.get("CL_BUILD_DIR", "build")
BIN = BUILD / "bin"
HAVE_SOLUTIONS = (ROOT / "solutions").is_dir()
PLOT_SKIPPED = 4  # a plot script's exit code when its input is not in DIR
PLOT_ERROR_LINES = 12  # of a failing plot script's stderr, shown

USAGE = """\
usage: ./course COMMAND [ARGS]

  demo [--out DIR]                   every lab's demo with the reference code -> DIR (out/)
  test                               unit tests, grading honesty, demo and plots (CI)
  grade [labNN ...] [--solutions] [--output FILE]
                                     graded tests: Score: X/Y, build/grade/results.json
  run labNN [ARGS]                   one lab executable (your code); labNN_solution: the reference
  plots [DIR]                        figures from the CSV/JSON in DIR (out/)
  bench [ARGS]                       the benchmarks (Google Benchmark ARGS pass through)
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

def build(log=sys.stdout):
    """Configure (first time) and build; show the tools' output only on failure."""
    print("building...", end=" ", file=log, flush=True)
    start = time.monotonic()
    try:
        if not (BUILD / "CMakeCache.txt").is_file():
            quiet(["cmake", "-S", str(ROOT), "-B", str(BUILD), "-DCMAKE_BUILD_TYPE=Release"],
                  "configure")
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


def run_demos(out, echo=True):
    """Run every lab's demo lines into OUT/<lab>; raise on the first failure."""
    suffix = "_solution" if HAVE_SOLUTIONS else ""
    if not HAVE_SOLUTIONS:
        print("no solutions/ here: the demo runs your code")
    labs = [lab for lab in lab_dirs() if demo_lines(lab)]
    if not labs:
        print("no lab has a demo.txt yet")
    for lab in labs:
        program = executable(lab + suffix)
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
    build()
    run_demos(out)
    outcomes = run_plots(out)
    print_summary_table(out)
    print(f"\noutputs: {show(out)}/")
    return 1 if plots_failed(outcomes) else 0


# ---------------------------------------------------------------- plots

def plot_scripts():
    """plots/*.py, sorted; `_name.py` files are helpers, not scripts."""
    return sorted(p for p in (ROOT / "plots").glob("*.py") if not p.name.startswith("_"))


def run_plots(directory, echo=True):
    """Run every plot script on DIRECTORY; return {script: (ok|skipped|failed, error lines)}."""
    env = dict(os.environ, MPLBACKEND="Agg")
    outcomes = {}
    for script in plot_scripts():
        done = subprocess.run([sys.executable, str(script.relative_to(ROOT)), str(directory)],
                              cwd=ROOT, env=env, capture_output=True, text=True, check=False)
        if done.returncode in (0, PLOT_SKIPPED):
            outcome = ("ok" if done.returncode == 0 else "skipped", [])
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

def grade_labs(labs, solutions):
    """Grade each lab against the reference code or the student's code."""
    suffix = "_tests_solution" if solutions else "_tests"
    return [grade.grade_lab(lab, BIN / (lab + suffix), ROOT) for lab in labs]


def print_grades(results):
    """Per-lab table, failed cases with their reason, problems, `Score: X/Y`."""
    fmt = grade.fmt_points
    rows = [["lab", "cases", "points"]]
    rows += [[r.lab, f"{len(r.passed)}/{len(r.cases)}", f"{fmt(r.score)}/{fmt(r.max_score)}"]
             for r in results]
    widths = [max(len(row[i]) for row in rows) for i in range(3)]
    for row in rows:
        print(f"{row[0]:<{widths[0]}}  {row[1]:>{widths[1]}}  {row[2]:>{widths[2]}}")
    for result in results:
        tag = grade.lab_id(result.lab)
        for case in result.failed:
            print(f'  FAIL {tag} "{case.name}" ({fmt(case.points)} pts): {case.reason}')
        for error in result.errors:
            print(f"  ERROR {error}")
    score = sum(r.score for r in results)
    max_score = sum(r.max_score for r in results)
    print(f"Score: {fmt(score)}/{fmt(max_score)}")


def cmd_grade(argv):
    parser = argparse.ArgumentParser(prog="course grade")
    parser.add_argument("labs", nargs="*", metavar="labNN", help="labs to grade (default: all)")
    parser.add_argument("--solutions", action="store_true", help="grade the reference code")
    parser.add_argument("--output", default=str(BUILD / "grade" / "results.json"),
                        help="Gradescope JSON (default build/grade/results.json)")
    args = parser.parse_args(argv)
    if args.solutions and not HAVE_SOLUTIONS:
        raise CourseError("--solutions: this copy has no solutions/", code=2)
    labs = list(dict.fromkeys(resolve_lab(token) for token in args.labs)) or lab_dirs()
    build()
    results = grade_labs(labs, args.solutions)
    print_grades(results)
    output = under_root(args.output)
    grade.write_gradescope(output, results)
    print(f"results: {show(output)}")
    return 1 if any(r.errors for r in results) else 0


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


def check_ctest(checks):
    done = subprocess.run(["ctest", "--test-dir", str(BUILD), "-L", "unit", "--output-on-failure"],
                          cwd=ROOT, capture_output=True, text=True, check=False)
    ok = done.returncode == 0
    lines = [line for line in done.stdout.splitlines() if "tests passed" in line]
    details = [] if ok else (done.stdout + done.stderr).splitlines()
    checks.record(ok, f"ctest -L unit: {lines[-1] if lines else 'no tests found'}", details)


def check_solutions(checks, labs):
    results = grade_labs(labs, solutions=True)
    grade.write_gradescope(BUILD / "grade" / "solutions" / "results.json", results)
    for r in results:
        fmt = grade.fmt_points
        details = [f'"{c.name}": {c.reason}' for c in r.failed] + r.errors
        ok = not details and bool(r.cases) and r.score == r.max_score
        checks.record(ok, f"{r.lab} solutions: {fmt(r.score)}/{fmt(r.max_score)}", details)


def check_stubs(checks, labs):
    results = grade_labs(labs, solutions=False)
    grade.write_gradescope(BUILD / "grade" / "stubs" / "results.json", results)
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
    results = grade_labs(labs, solutions=False)
    grade.write_gradescope(BUILD / "grade" / "results.json", results)
    fmt = grade.fmt_points
    for r in results:
        print(f"      {r.lab} (your code): {fmt(r.score)}/{fmt(r.max_score)}")
        for error in r.errors:
            print(f"        {error}")


def check_demo(checks, out):
    shutil.rmtree(out, ignore_errors=True)
    try:
        run_demos(out, echo=False)
    except CourseError as error:
        checks.record(False, f"demo: {error}", error.details)
        return
    checks.record(True, f"demo -> {show(out)}/")


def cmd_test(argv):
    argparse.ArgumentParser(prog="course test").parse_args(argv)
    checks = Checks()
    try:
        build()
    except CourseError as error:
        checks.record(False, str(error), error.details)
        return checks.finish()
    labs = lab_dirs()
    check_ctest(checks)
    if HAVE_SOLUTIONS:
        check_solutions(checks, labs)
        check_stubs(checks, labs)
    else:
        print("no solutions/ here: grading your code (a score, not a check)")
        report_student_score(labs)
        print("the demo and the plots run your code here: try them with ./course demo")
        return checks.finish()
    out = BUILD / "test-demo"
    check_demo(checks, out)
    for script, (status, error) in run_plots(out, echo=False).items():
        checks.record(status == "ok", f"plots/{script} on {show(out)}: {status}", error)
    return checks.finish()


# ---------------------------------------------------------------- run, bench

def cmd_run(argv):
    if not argv or argv[0].startswith("-"):
        raise CourseError("usage: ./course run labNN [ARGS]  (labNN_solution: the reference)", code=2)
    token, solution = argv[0], argv[0].endswith("_solution")
    if solution and not HAVE_SOLUTIONS:
        raise CourseError("this copy has no solutions/", code=2)
    lab = resolve_lab(token.removesuffix("_solution"))
    build(log=sys.stderr)
    program = executable(lab + ("_solution" if solution else ""))
    sys.stdout.flush()
    os.execv(program, [str(program), *argv[1:]])


def cmd_bench(argv):
    build()
    benches = sorted(p for p in BIN.glob("bench_*") if p.is_file() and os.access(p, os.X_OK))
    if not benches:
        print("no benchmarks yet")
        return 0
    failed = []
    for bench in benches:
        print(f"== {bench.name}", flush=True)
        if subprocess.run([str(bench), *argv], cwd=ROOT, check=False).returncode != 0:
            failed.append(bench.name)
    if failed:
        raise CourseError(f"failed: {' '.join(failed)}")
    return 0


# ---------------------------------------------------------------- main

COMMANDS = {"demo": cmd_demo, "test": cmd_test, "grade": cmd_grade, "run": cmd_run,
            "plots": cmd_plots, "bench": cmd_bench}


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
