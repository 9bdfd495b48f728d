"""./course plots: the figures, one script per family in plots/."""
import argparse
import os
import subprocess
import sys

from .base import ROOT, CourseError, show, under_root

PLOT_SKIPPED = 4  # a plot script's exit code when its input is not in DIR
PLOT_ERROR_LINES = 12  # of a failing plot script's stderr, shown


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
