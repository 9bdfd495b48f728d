#!/usr/bin/env python3
"""Lab 10, experiment 2: the 64² curtain for 3 s at (nearly) the same number of
projections per step, flat Gauss-Seidel against 2-4 levels: max and RMS strain
against time (from the `equal-cost-levels-N` runs of the demo: per_frame.csv
and the summary beside it). Writes equal_cost.png."""
from pathlib import Path

import _figures as figures
from _figures import plt

LAB = "lab10_hierarchical_pbd"
COMMAND = ("./course demo lab10  (or: " + figures.make_command(LAB, "--scene flat-curtain-64 --levels 3 "
           "--iterations-per-level 12 --steps 180 --out out/lab10_hierarchical_pbd/equal-cost-levels-3 "
           "--summary out/lab10_hierarchical_pbd/equal-cost-levels-3.json)"))


def main(out_dir):
    lab_dir = Path(out_dir) / LAB
    runs, sources = [], []
    for run_dir in sorted(lab_dir.glob("equal-cost-levels-*")):
        table, summary = run_dir / "per_frame.csv", lab_dir / (run_dir.name + ".json")
        if run_dir.is_dir() and table.exists() and summary.exists():
            runs.append((figures.summary(summary), figures.rows(table, ok_only=True)))
            sources += [table, summary]
    if not runs:
        return figures.skip("lab10_equal_cost", f"no {lab_dir}/equal-cost-levels-N/per_frame.csv; make them with "
                            f"{COMMAND}")
    target = lab_dir / "equal_cost.png"
    if figures.up_to_date(target, sources):
        return 0
    runs.sort(key=lambda run: run[0]["levels"])
    figure, (left, right) = plt.subplots(1, 2, figsize=(11.5, 4.6))
    for summary, rows in runs:
        t = [float(r["time"]) for r in rows[1:]]
        per_step = summary["projections"] / max(summary["steps"], 1)
        k = "/".join(str(v) for v in summary["iterations_per_level"])
        label = (f"{'flat Gauss-Seidel' if summary['levels'] == 1 else str(summary['levels']) + ' levels'}, "
                 f"K = {k}: {per_step:.3g} proj./step")
        left.semilogy(t, [float(r["max_strain"]) for r in rows[1:]], label=label)
        right.semilogy(t, [float(r["rms_strain"]) for r in rows[1:]], label=label)
    for axes, what in ((left, "max strain (the pinned corners)"), (right, "RMS strain over all constraints")):
        axes.set_xlabel("time (s)")
        axes.set_ylabel(what)
        axes.grid(True, which="major", alpha=0.3)
    left.legend(fontsize=8)
    scene = runs[0][0]["scene"]
    figure.suptitle(f"{scene}: strain at equal cost per step (Δt = {runs[0][0]['dt']:.4g} s, hard constraints; "
                    "K sweeps per level, the cloth first)", fontsize=11)
    figure.tight_layout(rect=(0, 0, 1, 0.94))
    figures.save(figure, target)
    return 0


if __name__ == "__main__":
    figures.run(main)
