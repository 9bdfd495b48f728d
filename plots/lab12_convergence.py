"""Lab 12 figures: one step's convergence, VBD against PD, accelerated PD and Newton.

Usage: /usr/bin/python3 plots/lab12_convergence.py OUTDIR
Reads every OUTDIR/lab12_vertex_block_descent/**/convergence.csv (the
--convergence lines of labs/lab12_vertex_block_descent/demo.txt) and, when
present, OUTDIR/lab11_acceleration/**/convergence.csv (lab 11's demo: PD, PD
with Chebyshev, L-BFGS, Newton on the same curtains; same columns), and writes
in OUTDIR/lab12_vertex_block_descent/, per scene that lab 12 ran:
  convergence_<scene>.png  relative objective error (g - g*)/g* against
                           iteration (left) and wall time (right), log scales
Without lab 11's data for a scene the figure has lab 12's curves only, says so
under its title, and the script says on stderr (the shared skip rule's form)
which command makes them. Exit 4 when lab 12's data are absent.
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


def lab11_hint(out_dir, scene):
    """Where lab 11's curves for `scene` come from: its demo, or the line of it for this scene."""
    return (f"PD, Chebyshev PD, L-BFGS and Newton need lab 11's run: ./course demo lab11, or "
            + figures.make_command(OTHER, f"--scene {scene} --convergence --method pd-chebyshev --iterations 3000 "
                                   f"--out {out_dir / OTHER}/exp1/chebyshev") + " (and --method pd, pd-lbfgs, newton)")


def draw(scene, curves, target, missing=None):
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
    if missing:
        figure.text(0.5, 0.90, missing, ha="center", fontsize=7, color="tab:red")
    figure.tight_layout(rect=(0, 0, 1, 0.9 if missing else 1))
    figures.save(figure, target, dpi=120)


def main(out_dir):
    lab_dir = out_dir / LAB
    tables = sorted(lab_dir.rglob("convergence.csv")) if lab_dir.is_dir() else []
    if not tables:
        return figures.skip("lab12_convergence", f"no convergence.csv under {lab_dir}; make one with " +
                            figures.make_command(LAB, f"--convergence --scene pd-curtain-32 --method vbd "
                                                 f"--iterations 3000 --out {lab_dir}/exp1/vbd") + " (or ./course demo lab12)")
    other_dir = out_dir / OTHER
    others = sorted(other_dir.rglob("convergence.csv")) if other_dir.is_dir() else []
    ours = read_runs(tables)
    theirs = read_runs(others)
    for scene, curves in ours.items():
        target = lab_dir / f"convergence_{scene}.png"
        if figures.up_to_date(target, tables + others):
            continue
        missing = None
        if not theirs.get(scene):
            figures.skip("lab12_convergence", f"{target.name}: no lab 11 curves for {scene}; "
                         + lab11_hint(out_dir, scene))
            missing = (f"No PD, Chebyshev PD, L-BFGS or Newton curve: they come from lab 11's run of {scene} "
                       "(./course demo lab11, or the --convergence lines of labs/lab11_acceleration/demo.txt)")
        draw(scene, {**theirs.get(scene, {}), **curves}, target, missing)
    return 0


if __name__ == "__main__":
    figures.run(main)
