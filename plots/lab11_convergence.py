"""Lab 11 figures: one step's convergence, accelerated against plain.

Usage: /usr/bin/python3 plots/lab11_convergence.py OUTDIR
Reads every OUTDIR/lab11_acceleration/**/convergence.csv, written by the
--convergence lines of labs/lab11_acceleration/demo.txt, and writes in
OUTDIR/lab11_acceleration/, per scene:
  convergence_<scene>.png  PD family: relative objective error (g - g*)/g* against
                           iteration (left) and wall time (right), log scales
  pbd_<scene>.png          PBD family: max strain against sweep, log scale
Exit 4 when the data are absent.
"""
import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

LAB = "lab11_acceleration"
COMMAND = ("./course run lab11 --convergence --scene pd-curtain-32 --method pd-chebyshev "
           "--out out/lab11_acceleration/chebyshev (or ./course demo)")
FLOOR = 1e-17  # an error of exactly 0 is drawn here
PBD = {"jacobi", "jacobi-chebyshev", "gauss-seidel"}


def label(row):
    method = row["method"]
    if method == "pd-lbfgs":
        return f"L-BFGS, m = {row['history']}"
    if method in ("pd-chebyshev", "jacobi-chebyshev"):
        return f"{method}, rho = {float(row['rho']):.7g}"
    return method


def read_runs(paths):
    """{scene: {label: [rows]}} over every table; later tables keep their own curves."""
    runs = {}
    for path in paths:
        with open(path, newline="") as handle:
            for row in csv.DictReader(handle):
                runs.setdefault(row["scene"], {}).setdefault(label(row), []).append(row)
    return runs


def draw_pd(scene, curves, path):
    figure, (by_iteration, by_time) = plt.subplots(1, 2, figsize=(12, 4.5))
    for name, rows in sorted(curves.items()):
        error = [max(float(row["objective_error"]), FLOOR) for row in rows]
        iteration = [max(int(row["iteration"]), 0.8) for row in rows]
        seconds = [max(float(row["seconds"]), 1e-6) for row in rows]
        marker = "o" if rows[0]["method"] == "newton" else None
        by_iteration.loglog(iteration, error, marker=marker, markersize=3, label=name)
        by_time.loglog(seconds, error, marker=marker, markersize=3, label=name)
    for axis in (by_iteration, by_time):
        for target in (1e-2, 1e-4, 1e-6):
            axis.axhline(target, color="0.6", linestyle=":", linewidth=1)
        axis.set_ylabel("relative objective error (g - g*) / g* (1)")
        axis.grid(True, which="major", alpha=0.3)
        axis.legend(fontsize=8)
    by_iteration.set_xlabel("iteration (iteration 0 drawn at 0.8)")
    by_time.set_xlabel("wall time of the step, factorization included (s)")
    figure.suptitle(f"Lab 11: one implicit-Euler step of {scene}; g* = lab 06's Newton minimum")
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)


def draw_pbd(scene, curves, path):
    figure, axis = plt.subplots(figsize=(7, 4.5))
    for name, rows in sorted(curves.items()):
        sweep = [int(row["iteration"]) for row in rows]
        strain = [max(float(row["max_strain"]), FLOOR) for row in rows]
        axis.semilogy(sweep, strain, label=name)
    axis.axhline(1e-3, color="0.6", linestyle=":", linewidth=1)
    axis.set_xlabel("sweep")
    axis.set_ylabel("max strain |l - L| / L (1)")
    axis.grid(True, which="major", alpha=0.3)
    axis.legend(fontsize=8)
    axis.set_title(f"Lab 11: one PBD step of {scene}")
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)


def main(argv):
    if len(argv) != 2:
        print("usage: plots/lab11_convergence.py OUTDIR", file=sys.stderr)
        return 2
    lab_dir = Path(argv[1]) / LAB
    tables = sorted(lab_dir.rglob("convergence.csv")) if lab_dir.is_dir() else []
    if not tables:
        print(f"lab11_convergence: no convergence.csv under {lab_dir}; make one with {COMMAND}", file=sys.stderr)
        return 4
    for scene, curves in read_runs(tables).items():
        pd = {name: rows for name, rows in curves.items() if rows[0]["method"] not in PBD}
        pbd = {name: rows for name, rows in curves.items() if rows[0]["method"] in PBD}
        if pd:
            draw_pd(scene, pd, lab_dir / f"convergence_{scene}.png")
        if pbd:
            draw_pbd(scene, pbd, lab_dir / f"pbd_{scene}.png")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
