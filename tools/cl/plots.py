"""./course plots: the figures, one script per family in plots/ (plots/_figures.py
is what they share).

A script draws only the figures whose data changed since they were drawn,
unless forced (CL_PLOTS_FORCE=1: ./course test, demo, bench and extremes, which
have just made their data). The terminal gets one line per figure drawn and one
summary line for the rest; -v lists what was skipped and why.
"""
import argparse
import json
import os
import queue
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from . import grade
from .base import ROOT, CourseError, show, under_root
from .labs import lab_dirs, resolve_lab

PLOT_SKIPPED = 4  # a plot script's exit code when its input is not in DIR (plots/_figures.py)
PLOT_ERROR_LINES = 12  # of a failing plot script's stderr, shown
PLOT_WORKERS = 2  # scripts drawn at once (each in a process forked from a runner, tools/cl/plot_worker.py;
#                   a process of its own where there is no fork)


@dataclass
class PlotOutcome:
    """One script's run: "ok", "skipped" (its data are absent) or "failed"."""

    status: str
    lines: list = field(default_factory=list)  # the skip reason, or the error
    drawn: list = field(default_factory=list)  # its `wrote PATH` lines
    current: list = field(default_factory=list)  # the figures it left as they were (up to date)


def plot_scripts(prefixes=None):
    """plots/*.py, sorted; `_name.py` files are helpers, not scripts. With
    `prefixes` (e.g. ["lab05"]), only the scripts whose name starts with one."""
    scripts = sorted(p for p in (ROOT / "plots").glob("*.py") if not p.name.startswith("_"))
    if prefixes is not None:
        scripts = [p for p in scripts if any(p.name.startswith(prefix + "_") for prefix in prefixes)]
    return scripts


class PlotWorkers:
    """PLOT_WORKERS runners (tools/cl/plot_worker.py), each with matplotlib
    imported once; a script runs in a process forked from one, as it would
    on its own. `run` may be called from PLOT_WORKERS threads at once."""

    def __init__(self):
        env = dict(os.environ, MPLBACKEND="Agg")
        self.idle = queue.Queue()
        self.processes = [subprocess.Popen([sys.executable, str(Path(__file__).with_name("plot_worker.py"))],
                                           cwd=ROOT, env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                           encoding="utf-8", errors="replace") for _ in range(PLOT_WORKERS)]
        for process in self.processes:
            self.idle.put(process)

    def run(self, script, directory, force):
        """(exit code, stdout, stderr) of `python3 SCRIPT DIRECTORY`, run in a worker."""
        process = self.idle.get()
        try:
            job = {"script": str(script.relative_to(ROOT)), "args": [show(directory)],
                   "env": {"CL_PLOTS_FORCE": "1" if force else "0"}}
            process.stdin.write(json.dumps(job) + "\n")
            process.stdin.flush()
            line = process.stdout.readline()
            if not line:
                return 1, "", f"the plot runner stopped (exit code {process.wait()})"
            result = json.loads(line)
            return result["code"], result["stdout"], result["stderr"]
        finally:
            self.idle.put(process)

    def close(self):
        for process in self.processes:
            process.stdin.close()
            process.wait()


def run_script(workers, script, directory, force):
    code, stdout, stderr = workers.run(script, directory, force)
    said = [line for line in stdout.splitlines() if line.strip()]
    drawn = [line for line in said if line.startswith("wrote ")]
    current = [line.removeprefix("up to date: ") for line in said if line.startswith("up to date: ")]
    if code == 0:
        return PlotOutcome("ok", [], drawn, current)
    if code == PLOT_SKIPPED:
        # The script's one line: the missing file and the command that makes it.
        reason = [line for line in (stderr + stdout).splitlines() if line.strip()]
        return PlotOutcome("skipped", reason[:1], drawn, current)
    error = [f"exit code {code}", *stderr.splitlines()[-PLOT_ERROR_LINES:]]
    return PlotOutcome("failed", error, drawn, current)


def run_plots(directory, echo=True, names=None, prefixes=None, force=True, verbose=False):
    """Run the plot scripts (those named, or those of `prefixes`, or all) on
    DIRECTORY, two at a time; return {script name: PlotOutcome}. With echo: one
    line per figure drawn, every failure, and one line for what was skipped
    (with verbose: each skipped figure and script)."""
    scripts = [s for s in plot_scripts(prefixes) if names is None or s.name in names]
    if not scripts:
        return {}
    workers = PlotWorkers()
    try:
        with ThreadPoolExecutor(max_workers=PLOT_WORKERS) as pool:
            outcomes = dict(zip((s.name for s in scripts),
                                pool.map(lambda script: run_script(workers, script, directory, force), scripts)))
    finally:
        workers.close()
    if echo:
        print_outcomes(outcomes, verbose)
    return outcomes


def print_outcomes(outcomes, verbose):
    for name, outcome in outcomes.items():
        for line in outcome.drawn:
            print(f"  {line}")
        if outcome.status == "failed":
            print(f"  plots/{name}: failed")
            for line in outcome.lines:
                print(f"    {line}")
        if verbose:
            for path in outcome.current:
                print(f"  up to date: {path}")
            if outcome.status == "skipped":
                reason = " ".join(outcome.lines).removeprefix(name.removesuffix(".py") + ": ")
                print(f"  plots/{name}: {reason}")
    current = sum(len(o.current) for o in outcomes.values())
    absent = [name for name, o in outcomes.items() if o.status == "skipped"]
    if current or absent:
        parts = [f"{current} figure{'s' if current != 1 else ''} up to date"] if current else []
        if absent:
            parts.append(f"{len(absent)} script{'s' if len(absent) != 1 else ''} without their data")
        more = "" if verbose else "; -v lists them"
        print(f"  skipped: {', '.join(parts)}{more}")
    elif not any(o.drawn for o in outcomes.values()) and not plots_failed(outcomes):
        print("  no figure to draw")


def plots_failed(outcomes):
    return any(outcome.status == "failed" for outcome in outcomes.values())


def parse_targets(tokens):
    """(directory, script prefixes or None) from `[labNN ...] [DIR]`: a DIR of
    one lab's runs (out/labNN_name) or of the benchmarks (out/bench) stands for
    its parent and that lab."""
    prefixes, directory = [], None
    for token in tokens:
        path = under_root(token)
        if path.is_dir() and (path.name in lab_dirs() or path.name == "bench"):
            prefixes.append(grade.lab_id(path.name) if path.name != "bench" else "bench")
            token = str(path.parent)
        elif not path.is_dir() and (token == "bench" or token.startswith("lab")):
            prefixes.append("bench" if token == "bench" else grade.lab_id(resolve_lab(token)))
            continue
        if directory is not None:
            raise CourseError(f"one DIR only (got {show(directory)} and {token})", code=2)
        directory = under_root(token)
    return directory or under_root("out"), (list(dict.fromkeys(prefixes)) or None)


def cmd_plots(argv):
    parser = argparse.ArgumentParser(prog="course plots")
    parser.add_argument("targets", nargs="*", metavar="[labNN ...] [DIR]",
                        help="labs whose figures to draw (default: all), and the directory with their "
                             "CSV/JSON (default out/; out/labNN_name works too)")
    parser.add_argument("-v", "--verbose", action="store_true",
                        help="also list the figures skipped, and the command that makes missing data")
    parser.add_argument("--force", action="store_true", help="redraw every figure, up to date or not")
    args = parser.parse_args(argv)
    directory, prefixes = parse_targets(args.targets)
    if not directory.is_dir():
        raise CourseError(f"{show(directory)} is not a directory (make it with ./course demo)", code=2)
    if not plot_scripts(prefixes):
        print("no plot scripts in plots/ yet" if prefixes is None else
              f"no plot scripts in plots/ for {', '.join(prefixes)}")
    outcomes = run_plots(directory, prefixes=prefixes, force=args.force, verbose=args.verbose)
    return 1 if plots_failed(outcomes) else 0
