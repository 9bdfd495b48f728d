"""./course demo and ./course run: the labs' executables."""
import argparse
import json
import os
import shlex
import subprocess
import sys

from .base import ROOT, CourseError, show, under_root
from .build import BuildFailure, build_targets, configure
from .labs import demo_lines, executable, lab_dirs, manifest, resolve_lab
from .plots import plots_failed, run_plots


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


def cmd_run(argv):
    if not argv or argv[0].startswith("-"):
        raise CourseError("usage: ./course run labNN [ARGS]  (labNN_solution: the reference, where solutions/ holds it)", code=2)
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
