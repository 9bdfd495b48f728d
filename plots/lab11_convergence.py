"""Lab 11 figures: one step's convergence, accelerated against plain.

Usage: /usr/bin/python3 plots/lab11_convergence.py [OUTDIR]
Reads every OUTDIR/lab11_acceleration/**/convergence.csv, written by the
--convergence lines of labs/lab11_acceleration/demo.txt, and writes in
OUTDIR/lab11_acceleration/, per scene:
  convergence_<scene>.png  PD family: relative objective error (g - g*)/g* against
                           iteration (left) and wall time (right), log scales
  pbd_<scene>.png          PBD family: max strain against sweep, log scale
A figure newer than every table it is drawn from is left as it is; exit 4
(the shared skip rule, _figures.py) when the data are absent.
"""
from pathlib import Path

import _figures as figures
from _figures import plt

LAB = "lab11_acceleration"
COMMAND = ("./course demo lab11  (or: " + figures.make_command(
    LAB, "--convergence --scene pd-curtain-32 --method pd-chebyshev --out out/lab11_acceleration/chebyshev") + ")")
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
    """{(scene, family): ({label: [rows]}, {the tables they come from})}, family
    "pd" or "pbd" (the two figures); later tables keep their own curves."""
    runs = {}
    for path in paths:
        for row in figures.rows(path):
            family = "pbd" if row["method"] in PBD else "pd"
            curves, sources = runs.setdefault((row["scene"], family), ({}, set()))
            curves.setdefault(label(row), []).append(row)
            sources.add(path)
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
    figures.save(figure, path, dpi=120)


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
    figures.save(figure, path, dpi=120)


def main(out_dir):
    lab_dir = Path(out_dir) / LAB
    tables = sorted(lab_dir.rglob("convergence.csv")) if lab_dir.is_dir() else []
    if not tables:
        return figures.skip("lab11_convergence", f"no convergence.csv under {lab_dir}; make one with {COMMAND}")
    for (scene, family), (curves, sources) in read_runs(tables).items():
        target = lab_dir / (f"convergence_{scene}.png" if family == "pd" else f"pbd_{scene}.png")
        if not figures.up_to_date(target, sorted(sources)):
            (draw_pd if family == "pd" else draw_pbd)(scene, curves, target)
    return 0


if __name__ == "__main__":
    figures.run(main)
