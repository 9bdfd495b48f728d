"""Lab 13 figures: one step to its converged result, against the stiffness.

Usage: /usr/bin/python3 plots/lab13_convergence.py OUTDIR
Reads every OUTDIR/lab13_constrained_newton/**/crossover.csv and the
convergence.csv beside it (the --convergence lines of
labs/lab13_constrained_newton/demo.txt) and writes, beside each:
  iterations_vs_k.png       iterations to a relative distance 1e-6 of the
                            converged step against finite k, per method (a method
                            that did not get there within its cap is drawn at the
                            top with an open marker); none for a hard-only sweep
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
    """False when the table has no finite k (a hard-only sweep): no figure."""
    runs = {}
    for row in figures.rows(crossover):
        k = float(row["stiffness"])
        if math.isinf(k):
            continue
        runs.setdefault((row["scene"], run_label(row)), []).append(row)
    if not runs:
        return False
    figure, axis = plt.subplots(figsize=(9, 4.5))
    # One colour per run (a colour map with as many as there are runs: the
    # default cycle has ten), one marker per scene.
    colours = plt.get_cmap("tab20")
    scenes = sorted({scene for scene, _ in runs})
    markers = "osD^v<>"
    missed = []  # (k, colour, marker) of the runs that did not reach 1e-6, drawn at the top once the axis is set
    for index, ((scene, name), found) in enumerate(sorted(runs.items())):
        ks = [float(r["stiffness"]) for r in found]
        counts = [int(r["iterations_1e-6"]) if r["iterations_1e-6"] else math.nan for r in found]
        colour = colours(index % 20)
        marker = markers[scenes.index(scene) % len(markers)]
        axis.semilogx(ks, counts, "-", marker=marker, markersize=4, color=colour, label=f"{scene}: {name}")
        missed += [(k, colour, marker) for k, c in zip(ks, counts) if math.isnan(c)]
    axis.set_ylim(bottom=0)
    top = axis.get_ylim()[1]
    for k, colour, marker in missed:
        axis.semilogx([k], [top], marker, markerfacecolor="none", color=colour, clip_on=False)
    figures.finish(axis, "spring stiffness k (N/m)", "iterations to a relative distance 1e-6 (1)", legend=None)
    # The legend beside the axes, where it covers no data.
    axis.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    axis.set_title("Lab 13: iterations to the implicit step against k (open: not reached)")
    figure.tight_layout()
    figures.save(figure, target, dpi=120)
    return True


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
                                                 f"--out {lab_dir}/exp1") + " (or ./course demo lab13)")
    for crossover in tables:
        convergence = crossover.with_name("convergence.csv")
        sources = [crossover] + ([convergence] if convergence.is_file() else [])
        target = crossover.with_name("iterations_vs_k.png")
        if not figures.up_to_date(target, sources):
            draw_iterations(crossover, target)  # nothing for a hard-only sweep (k = inf has no place on the axis)
        if not convergence.is_file():
            continue
        for scene in sorted({r["scene"] for r in figures.rows(crossover)}):
            target = crossover.with_name(f"convergence_{scene}.png")
            if not figures.up_to_date(target, sources):
                draw_curves(convergence, scene, target)
    return 0


if __name__ == "__main__":
    figures.run(main)
