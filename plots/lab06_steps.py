"""Lab 06 figure: runs of steps, per step.

Usage: /usr/bin/python3 plots/lab06_steps.py OUTDIR
Reads OUTDIR/lab06_projective_dynamics/<run>/per_step.csv (the step runs of
labs/lab06_projective_dynamics/demo.txt) and writes <run>/steps.png: the step's
final objective, its iterations and wall time, and the max strain, against time.
Exit 4 when no run is there.
"""
import _figures as figures
from _figures import plt

LAB = "lab06_projective_dynamics"
COMMAND = figures.make_command(LAB, "--scene pd-curtain-32 --out out/lab06_projective_dynamics/curtain-32-pd "
                               "(or ./course demo lab06)")


def draw(rows, title, path):
    time = [float(row["time"]) for row in rows]
    figure, axes = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    panels = [(axes[0][0], "objective", "final objective g of the step (J)", True),
              (axes[0][1], "iterations", "iterations done", False),
              (axes[1][0], "seconds", "wall time of the step (s)", True),
              (axes[1][1], "max_strain", "max strain error (1; m for rest length 0)", True)]
    for axis, key, label, logarithmic in panels:
        values = [float(row[key]) for row in rows]
        if logarithmic and all(value > 0 for value in values):
            axis.semilogy(time, values)
        else:
            axis.plot(time, values)
        axis.set_ylabel(label)
        axis.grid(True, alpha=0.3)
    for axis in axes[1]:
        axis.set_xlabel("simulated time (s)")
    bad = [row for row in rows if row["status"] != "ok"]
    figure.suptitle(title + (f" — {bad[0]['status']}" if bad else ""))
    figure.tight_layout()
    figures.save(figure, path)


def main(out_dir):
    lab_dir = out_dir / LAB
    runs = sorted(lab_dir.glob("*/per_step.csv"))
    if not runs:
        return figures.skip("lab06_steps", f"no {lab_dir}/<run>/per_step.csv; make one with {COMMAND}")
    for table in runs:
        if figures.up_to_date(table.parent / "steps.png", [table]):
            continue
        rows = [row for row in figures.rows(table) if int(row["step"]) > 0]
        if rows:
            draw(rows, f"Lab 06: {table.parent.name}, per step", table.parent / "steps.png")
    return 0


if __name__ == "__main__":
    figures.run(main)
