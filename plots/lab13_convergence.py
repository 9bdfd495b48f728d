"""Lab 13 figures: one step to its converged result, against the stiffness.

Usage: /usr/bin/python3 plots/lab13_convergence.py OUTDIR
Reads every OUTDIR/lab13_constrained_newton/**/crossover.csv and the
convergence.csv beside it (the --convergence lines of
labs/lab13_constrained_newton/demo.txt) and writes, beside each:
  iterations_vs_k.png       iterations to a relative distance 1e-6 of the
                            converged step against k, per method (a method that
                            did not get there within its cap is drawn at the cap
                            with an open marker)
  convergence_<scene>.png   relative distance against iteration, one panel per k
Exit 4 when the data are absent.
"""
import math

import _figures as figures
from _figures import plt

LAB = "lab13_constrained_newton"
FLOOR = 1e-16  # a distance of exactly 0 is drawn here


def run_label(row):
    if row["method"] == "constrained-newton":
        return f"constrained Newton (x0 = {row['start']}, lambda0 = {row['warm']})"
    return f"{row['method']} (lab 06)"


def draw_iterations(crossover, target):
    figure, axis = plt.subplots(figsize=(7, 4.5))
    runs = {}
    for row in figures.rows(crossover):
        k = float(row["stiffness"])
        if math.isinf(k):
            continue
        runs.setdefault((row["scene"], run_label(row)), []).append(row)
    missed = []  # (k, colour) of the runs that did not reach 1e-6, drawn at the top once the axis is set
    for (scene, name), found in sorted(runs.items()):
        ks = [float(r["stiffness"]) for r in found]
        counts = [int(r["iterations_1e-6"]) if r["iterations_1e-6"] else math.nan for r in found]
        line, = axis.loglog(ks, counts, "-o", markersize=4, label=f"{scene}: {name}")
        missed += [(k, line.get_color()) for k, c in zip(ks, counts) if math.isnan(c)]
    top = axis.get_ylim()[1]
    for k, colour in missed:
        axis.loglog([k], [top], "o", markerfacecolor="none", color=colour, clip_on=False)
    figures.finish(axis, "spring stiffness k (N/m)", "iterations to a relative distance 1e-6 (1)")
    axis.set_title("Lab 13: iterations to the implicit step against k (open: not reached)")
    figure.tight_layout()
    figures.save(figure, target, dpi=120)


def draw_curves(convergence, scene, target):
    rows = [r for r in figures.rows(convergence) if r["scene"] == scene]
    stiffnesses = sorted({float(r["stiffness"]) for r in rows})
    figure, axes = plt.subplots(1, len(stiffnesses), figsize=(4.2 * len(stiffnesses), 4), squeeze=False)
    for axis, k in zip(axes[0], stiffnesses):
        curves = {}
        for r in rows:
            if float(r["stiffness"]) == k:
                curves.setdefault(run_label(r), []).append(r)
        for name, found in sorted(curves.items()):
            iterations = [max(int(r["iteration"]), 0.8) for r in found]
            distances = [max(float(r["distance"]), FLOOR) for r in found]
            axis.loglog(iterations, distances, "-" if "constrained" in name else "--", label=name)
        axis.axhline(1e-6, color="0.6", linestyle=":", linewidth=1)
        figures.finish(axis, "iteration (0 drawn at 0.8)", "relative distance to the step (1)", legend=6)
        axis.set_title(f"k = {k:g} N/m")
    figure.suptitle(f"Lab 13: one implicit-Euler step of {scene}")
    figure.tight_layout()
    figures.save(figure, target, dpi=110)


def main(out_dir):
    lab_dir = out_dir / LAB
    tables = sorted(lab_dir.rglob("crossover.csv")) if lab_dir.is_dir() else []
    if not tables:
        return figures.skip("lab13_convergence", f"no crossover.csv under {lab_dir}; make one with " +
                            figures.make_command(LAB, f"--convergence --sweep-scenes pd-curtain-16 "
                                                 f"--out {lab_dir}/exp1") + " (or ./course demo)")
    for crossover in tables:
        convergence = crossover.with_name("convergence.csv")
        sources = [crossover] + ([convergence] if convergence.is_file() else [])
        target = crossover.with_name("iterations_vs_k.png")
        if not figures.up_to_date(target, sources):
            draw_iterations(crossover, target)
        if not convergence.is_file():
            continue
        for scene in sorted({r["scene"] for r in figures.rows(crossover)}):
            target = crossover.with_name(f"convergence_{scene}.png")
            if not figures.up_to_date(target, sources):
                draw_curves(convergence, scene, target)
    return 0


if __name__ == "__main__":
    figures.run(main)
