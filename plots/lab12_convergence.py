"""Lab 12 figures: one step's convergence, VBD against PD, accelerated PD and Newton.

Usage: /usr/bin/python3 plots/lab12_convergence.py OUTDIR
Reads every OUTDIR/lab12_vertex_block_descent/**/convergence.csv (the
--convergence lines of labs/lab12_vertex_block_descent/demo.txt) and, when
present, OUTDIR/lab11_acceleration/**/convergence.csv (lab 11's demo: PD, PD
with Chebyshev, L-BFGS, Newton on the same curtains; same columns), and writes
in OUTDIR/lab12_vertex_block_descent/, per scene that lab 12 ran:
  convergence_<scene>.png  relative objective error (g - g*)/g* against
                           iteration (left) and wall time (right), log scales
Exit 4 when lab 12's data are absent.
"""
import _figures as figures
from _figures import plt

LAB = "lab12_vertex_block_descent"
OTHER = "lab11_acceleration"
FLOOR = 1e-17  # an error of exactly 0 is drawn here
PBD = {"jacobi", "jacobi-chebyshev", "gauss-seidel"}


def label(row):
    method = row["method"]
    if method == "pd-lbfgs":
        return f"L-BFGS, m = {row['history']} (lab 11)"
    if method in ("pd-chebyshev", "vbd-chebyshev"):
        return f"{method}, rho = {float(row['rho']):.6g}" + (" (lab 11)" if method == "pd-chebyshev" else "")
    if method in ("pd", "newton"):
        return method + " (lab 11)"
    return method


def read_runs(paths):
    """{scene: {label: [rows]}} over every table."""
    runs = {}
    for path in paths:
        for row in figures.rows(path):
            if row["method"] in PBD:
                continue
            runs.setdefault(row["scene"], {}).setdefault(label(row), []).append(row)
    return runs


def draw(scene, curves, target):
    figure, (by_iteration, by_time) = plt.subplots(1, 2, figsize=(12, 4.5))
    for name, found in sorted(curves.items()):
        error = [max(float(row["objective_error"]), FLOOR) for row in found]
        iteration = [max(int(row["iteration"]), 0.8) for row in found]
        seconds = [max(float(row["seconds"]), 1e-6) for row in found]
        style = "-" if found[0]["method"].startswith("vbd") else "--"
        marker = "o" if found[0]["method"] == "newton" else None
        by_iteration.loglog(iteration, error, style, marker=marker, markersize=3, label=name)
        by_time.loglog(seconds, error, style, marker=marker, markersize=3, label=name)
    for axis in (by_iteration, by_time):
        for level in (1e-2, 1e-4, 1e-6):
            axis.axhline(level, color="0.6", linestyle=":", linewidth=1)
    figures.finish(by_iteration, "iteration or sweep (0 drawn at 0.8)", "relative objective error (g - g*) / g* (1)")
    figures.finish(by_time, "wall time of the step (s)", "relative objective error (g - g*) / g* (1)")
    figure.suptitle(f"Lab 12: one implicit-Euler step of {scene}; g* = lab 06's Newton minimum")
    figure.tight_layout()
    figures.save(figure, target, dpi=120)


def main(out_dir):
    lab_dir = out_dir / LAB
    tables = sorted(lab_dir.rglob("convergence.csv")) if lab_dir.is_dir() else []
    if not tables:
        return figures.skip("lab12_convergence", f"no convergence.csv under {lab_dir}; make one with " +
                            figures.make_command(LAB, f"--convergence --scene pd-curtain-32 --method vbd "
                                                 f"--iterations 3000 --out {lab_dir}/exp1/vbd") + " (or ./course demo)")
    other_dir = out_dir / OTHER
    others = sorted(other_dir.rglob("convergence.csv")) if other_dir.is_dir() else []
    ours = read_runs(tables)
    theirs = read_runs(others)
    for scene, curves in ours.items():
        target = lab_dir / f"convergence_{scene}.png"
        if figures.up_to_date(target, tables + others):
            continue
        draw(scene, {**theirs.get(scene, {}), **curves}, target)
    return 0


if __name__ == "__main__":
    figures.run(main)
