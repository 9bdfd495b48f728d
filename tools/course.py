"""Constraint Labs driver: build, demo, test, grade, run, plots, bench.

Started by ../course (or ../course.cmd on Windows), which picks a Python.
Before a command runs, what it needs is checked by what the system can do
(tools/cl/requirements.py: installed with apt on Debian as root, else one line
saying how). The commands live in the package tools/cl/, one module per
concern (docs/DESIGN.md §1); this file only dispatches. Paths are relative to
the course root, not the cwd.
"""
import argparse
import os
import sys

from cl.autograder import cmd_autograder
from cl.base import CourseError
from cl.checks import cmd_test
from cl.claims import cmd_claims
from cl.demo import cmd_demo, cmd_run
from cl.fuzz import cmd_fuzz
from cl.grading import cmd_grade
from cl.handouts import cmd_handouts
from cl.lanes import cmd_lanes
from cl.live import cmd_live
from cl.measure import cmd_bench, cmd_extremes
from cl.mistakes import cmd_mistakes
from cl.plots import cmd_plots
from cl.release import cmd_release
from cl.requirements import ensure
from cl.sanitize import cmd_sanitize
from cl.view import cmd_view

USAGE = """\
usage: ./course COMMAND [ARGS]

  demo [labNN ...] [--out DIR] [--quick]
                                     every lab's demo with its reference code -> DIR (out/), its
                                     views and DIR/index.html; labNN: that lab's demo with your code
  test                               unit tests, grading honesty, demo and plots (CI)
  grade [labNN ...] [-t PATTERN] [-v] [--solutions] [--output FILE]
                                     graded tests (each lab built on its own): Score: X/Y,
                                     build/grade/results.json; -t: only matching cases,
                                     -v: list passing cases too, and what each lab's tests and
                                     executable link
  release labNN DIR                  the student tree for lab NN's week: stubs, and the
                                     reference code of the labs before NN
  autograder labNN [--out FILE.zip]  the Gradescope autograder for lab NN (its hidden tests
                                     too): build/gradescope/labNN.zip
  view DIR [DIR2] [--output FILE]    DIR/view.html: a self-contained 3-D player of a run's frames
                                     (a lab run with --frames N --out DIR); DIR2: two runs side by
                                     side in view-DIR-vs-DIR2.html beside DIR (DIR/view.html kept)
  run labNN [ARGS]                   one lab executable (your code); labNN_solution: the reference,
                                     where solutions/ holds it
  live labNN [--port N] [ARGS]       the lab running live beside a page in the browser: drag the
                                     cloth, pin it (shift-click), turn the knobs; prints the page's
                                     URL (127.0.0.1 only); Ctrl-C or the page's stop ends it
  plots [labNN ...] [DIR] [-v]       the figures whose CSV/JSON in DIR (out/, or out/labNN_name)
                                     changed since drawn; -v: list the rest, --force: redraw all
  bench [--quick] [--micro ARGS]     the speed/accuracy trade of every method -> out/bench (bench/README.md)
  extremes [--quick]                 the extremes matrix: finite, reported or silent NaN -> out/bench
  handouts [labNN ...]               every command each handout shows, checked in its week's tree
                                     (the lab's executable with --check: nothing is written;
                                     instructor)
  claims [labNN ...] [--quick] [--solutions]
                                     every number a handout quotes, reproduced by its command
                                     (labs/*/claims.json); --quick: those that take seconds
  mistakes [labNN ...] [--all-cases] the catalogued student mistakes (solutions/*/mistakes.json),
                                     each planted: the grader must catch it (instructor)
  fuzz [SECONDS]                     fuzz the scene loader with libFuzzer (clang; default 60 s)
  sanitize                           the whole test suite under AddressSanitizer and UBSan (build-asan)
  setup [--all]                      install what the student's commands need (Debian and Ubuntu
                                     as root), or print the one line that does; --all: the
                                     instructor's too (what ./course test needs)
  lanes [libcxx] [mingw]             the course built with clang + libc++ (macOS's toolchain) and
                                     MinGW-w64 (Windows'), its references graded there (Wine for
                                     Windows) -> build/lanes/ (CI, after ./course test)
  help                               this text

Paths are relative to the course root; CL_BUILD_DIR overrides build/."""

def cmd_setup(argv):
    """./course setup [--all]: what the commands need, installed or told, at once
    rather than at a command's first run (the dev container's image runs it)."""
    parser = argparse.ArgumentParser(prog="course setup", description="install what the course needs")
    parser.add_argument("--all", action="store_true", help="the instructor's too (what ./course test needs)")
    args = parser.parse_args(argv)
    code, missing = ensure("test" if args.all else "demo")
    if missing:
        print(missing, file=sys.stderr)
    else:
        who = "every command needs" if args.all else "the student's commands need"
        print(f"course setup: what {who} is installed")
    return code


COMMANDS = {"demo": cmd_demo, "test": cmd_test, "grade": cmd_grade, "run": cmd_run,
            "plots": cmd_plots, "bench": cmd_bench, "extremes": cmd_extremes, "fuzz": cmd_fuzz, "sanitize": cmd_sanitize,
            "release": cmd_release, "handouts": cmd_handouts, "claims": cmd_claims, "mistakes": cmd_mistakes, "autograder": cmd_autograder, "view": cmd_view, "live": cmd_live,
            "setup": cmd_setup, "lanes": cmd_lanes}


def main(argv):
    if os.name == "nt":  # a redirected stdout is the locale's (cp1252) there: the course prints UTF-8 (−, ², ≥)
        for stream in (sys.stdout, sys.stderr):
            stream.reconfigure(encoding="utf-8", errors="replace")
    if not argv or argv[0] in ("help", "-h", "--help"):
        print(USAGE)
        return 0
    command = COMMANDS.get(argv[0])
    if command is None:
        print(f"course: unknown command '{argv[0]}' (try ./course help)", file=sys.stderr)
        return 2
    code, missing = ensure(argv[0])
    if missing:
        print(missing, file=sys.stderr)
    if code:
        return code
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
