"""Lab 06 figures: one step's convergence, projective dynamics against Newton.

Usage: /usr/bin/python3 plots/lab06_convergence.py OUTDIR
Reads OUTDIR/lab06_projective_dynamics/convergence.csv (and wrinkled/convergence.csv
when present), written by the --convergence lines of labs/lab06_projective_dynamics/demo.txt,
and writes next to each CSV, per scene:
  convergence_<scene>.png   relative objective error (g - g*)/g* against iteration (left)
                            and against wall time (right), log scales
Exit 4 when the data are absent.
"""
import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

LAB = "lab06_projective_dynamics"
COMMAND = ("./course run lab06_solution --convergence --sweep-scenes "
           "pd-curtain-16,pd-curtain-32,pd-curtain-64,pd-curtain-128 --out out/lab06_projective_dynamics "
           "(or ./course demo)")
FLOOR = 1e-17  # an error of exactly 0 (the reference itself) is drawn here
STYLE = {"pd": {"color": "tab:blue", "label": "projective dynamics (1 factorization)"},
         "newton": {"color": "tab:red", "marker": "o", "markersize": 3,
                    "label": "Newton (1 factorization per iteration)"}}
TARGETS = (1e-2, 1e-3, 1e-6)


def read_runs(path):
    """{scene: {method: [rows]}} from a convergence.csv."""
    runs = {}
    with open(path, newline="") as handle:
        for row in csv.DictReader(handle):
            runs.setdefault(row["scene"], {}).setdefault(row["method"], []).append(row)
    return runs


def draw(scene, methods, path):
    figure, (by_iteration, by_time) = plt.subplots(1, 2, figsize=(12, 4.5))
    for method, rows in methods.items():
        error = [max(float(row["relative_error"]), FLOOR) for row in rows]
        iteration = [int(row["iteration"]) for row in rows]
        seconds = [float(row["seconds"]) for row in rows]
        style = STYLE.get(method, {"label": method})
        by_iteration.loglog([max(i, 0.8) for i in iteration], error, **style)
        by_time.loglog(seconds, error, **style)
        if method == "pd":
            # Without the one factorization: the cost once it is amortised over a scene.
            setup = float(rows[0]["setup_seconds"])
            by_time.loglog([s - setup for s in seconds[1:]], error[1:], color="tab:blue", linestyle=":",
                           label="projective dynamics, factorization not counted")
    for axis in (by_iteration, by_time):
        for target in TARGETS:
            axis.axhline(target, color="0.6", linestyle=":", linewidth=1)
        axis.set_ylabel("relative objective error (g - g*) / g* (1)")
        axis.grid(True, which="major", alpha=0.3)
    by_iteration.set_xlabel("iteration (iteration 0 drawn at 0.8)")
    by_time.set_xlabel("wall time of the step (s)")
    by_iteration.legend(fontsize=8)
    by_time.legend(fontsize=8)
    first = next(iter(methods.values()))[0]
    note = "" if first["reference_converged"] == "1" else \
        f" (g* known to about {float(first['reference_last_decrease']):.0e})"
    figure.suptitle(f"Lab 06: one implicit-Euler step of {scene}, {first['unknowns']} unknowns{note}; "
                    f"zero error drawn at {FLOOR:g}")
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)


def main(argv):
    if len(argv) != 2:
        print("usage: plots/lab06_convergence.py OUTDIR", file=sys.stderr)
        return 2
    lab_dir = Path(argv[1]) / LAB
    tables = [path for path in (lab_dir / "convergence.csv", lab_dir / "wrinkled" / "convergence.csv")
              if path.is_file()]
    if not tables:
        print(f"lab06_convergence: {lab_dir / 'convergence.csv'} is missing; make it with {COMMAND}",
              file=sys.stderr)
        return 4
    for table in tables:
        for scene, methods in read_runs(table).items():
            draw(scene, methods, table.parent / f"convergence_{scene}.png")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
