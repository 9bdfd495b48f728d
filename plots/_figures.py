"""What every plot script shares (one script per figure family imports it).

- the command line: `plots/NAME.py [OUTDIR]` (default out/), through `run(main)`;
- loading: CSV rows, numeric columns, a run's JSON summary;
- the skip rule: when its data are not in OUTDIR a script prints one line, the
  missing file and the command that makes it (`make_command`: the reference
  where this tree has one, else the student's executable), and exits SKIPPED;
- whether a figure is up to date: drawn after every file it is drawn from
  (`up_to_date`, which says so in one line; CL_PLOTS_FORCE=1 redraws anyway);
- saving: `save` writes the figure, closes it and prints `wrote PATH`;
- pyplot is imported on first use (and a script imports matplotlib's other
  modules inside the function that draws), so a script with nothing to draw
  takes a tenth of a second.
"""
import csv
import json
import os
import sys
from pathlib import Path

SKIPPED = 4  # the exit code of a script whose data are not in OUTDIR (tools/cl/plots.py)
ROOT = Path(__file__).resolve().parent.parent
FORCE = "CL_PLOTS_FORCE"  # set to 1: draw every figure, up to date or not


class _Pyplot:
    """matplotlib.pyplot on the Agg backend, imported when first used."""

    def __getattr__(self, name):
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as pyplot

        return getattr(pyplot, name)


plt = _Pyplot()


def run(main):
    """Exit with main(OUTDIR): the first argument, default out/."""
    sys.exit(main(Path(sys.argv[1] if len(sys.argv) > 1 else "out")))


# ---------------------------------------------------------------- loading

def rows(path, ok_only=False):
    """A CSV file's rows as dicts of text; with ok_only those whose status is "ok"."""
    with open(path, newline="", encoding="utf-8") as handle:
        found = list(csv.DictReader(handle))
    return [r for r in found if r["status"] == "ok"] if ok_only else found


def numeric_rows(path):
    """A CSV file's rows as dicts of floats."""
    return [{key: float(value) for key, value in row.items()} for row in rows(path)]


def columns(path):
    """A CSV file as {column: [floats]} ({} when it has no rows)."""
    found = rows(path)
    return {key: [float(row[key]) for row in found] for key in found[0]} if found else {}


def column(found, name):
    return [float(r[name]) for r in found]


def number(text):
    """A CSV cell as a float; an empty cell as None."""
    return float(text) if text not in ("", None) else None


def summary(path):
    """A run's JSON summary, or {} when there is none."""
    path = Path(path)
    return json.loads(path.read_text(encoding="utf-8")) if path.exists() else {}


# ---------------------------------------------------------------- skip, up to date, save

def make_command(lab, args):
    """`./course run labNN ARGS` with the executable that exists in this tree:
    the reference (labNN_solution) where solutions/LAB is present, else the
    student's own."""
    tag = lab.split("_", 1)[0]
    name = tag + ("_solution" if (ROOT / "solutions" / lab).is_dir() else "")
    return f"./course run {name} {args}"


def skip(script, message):
    """Print `SCRIPT: MESSAGE` (the missing data and the command that makes it); return SKIPPED."""
    print(f"{script}: {message}", file=sys.stderr)
    return SKIPPED


def up_to_date(targets, sources):
    """True (and one line saying so) when every target exists and was written
    after every source and after the script that draws it; always False with
    CL_PLOTS_FORCE=1."""
    targets = [Path(t) for t in ([targets] if isinstance(targets, (str, Path)) else targets)]
    if os.environ.get(FORCE) == "1" or not all(t.exists() for t in targets):
        return False
    drawn_by = [Path(sys.argv[0]), Path(__file__)]  # a changed script redraws its figures
    newest = max((Path(s).stat().st_mtime for s in [*sources, *drawn_by] if Path(s).exists()), default=0.0)
    if min(t.stat().st_mtime for t in targets) < newest:
        return False
    print(f"up to date: {targets[0]}")
    return True


def save(figure, target, dpi=110):
    """Write `figure` to `target`, close it, say so."""
    figure.savefig(target, dpi=dpi)
    plt.close(figure)
    print(f"wrote {target}")


def write_table(target, text):
    """Write a Markdown table beside a figure, say so."""
    Path(target).write_text(text, encoding="utf-8")
    print(f"wrote {target}")


def finish(axes, xlabel, ylabel, legend=8, which="major"):
    """Label both axes, a light grid, and a legend in `legend`-point type (None: no legend)."""
    axes.set_xlabel(xlabel)
    axes.set_ylabel(ylabel)
    axes.grid(True, which=which, alpha=0.3)
    if legend:
        axes.legend(fontsize=legend)
