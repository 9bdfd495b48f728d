#!/usr/bin/env python3
"""Lab 04: strain and energy against time for each single run (per_frame.csv
of `lab04_pbd --out DIR`): how fast PBD damps, and where the energy goes.
Hard constraints store no energy, so while the mesh is stretched the total
(kinetic + potential) dips below its start and comes back as it contracts;
what stays lost is the solver's damping.

One PNG per run: OUTDIR/lab04_pbd/<run>/history.png."""
import _figures as figures
from _figures import plt

LAB = "lab04_pbd"


def draw(source, summary, target):
    rows = figures.rows(source, ok_only=True)
    time = figures.column(rows, "time")
    figure, (left, right) = plt.subplots(1, 2, figsize=(11.0, 4.0))
    max_strain, rms_strain = figures.column(rows, "max_strain"), figures.column(rows, "rms_strain")
    # From frame 1: the start is at rest length up to round-off (or a tiny jitter).
    if max(max_strain[1:], default=0.0) < 1e-12:
        left.plot(time, max_strain, label="max strain")
        left.text(0.5, 0.5, f"round-off only: max {max(max_strain):.1e}", transform=left.transAxes,
                  ha="center", fontsize=10)
    elif any(value > 0 for value in max_strain[1:]):
        left.semilogy(time[1:], [max(v, 1e-17) for v in max_strain[1:]], label="max strain")
        left.semilogy(time[1:], [max(v, 1e-17) for v in rms_strain[1:]], label="RMS strain")
    else:
        left.plot(time, max_strain, label="max strain")
    figures.finish(left, "time (s)", "strain  |l − L| / L")
    kinetic, potential, total = figures.column(rows, "kinetic"), figures.column(rows, "potential"), figures.column(rows, "total_energy")
    right.plot(time, [k - kinetic[0] for k in kinetic], label="kinetic − start")
    right.plot(time, [p - potential[0] for p in potential], label="potential − start")
    right.plot(time, [e - total[0] for e in total], "k", lw=2, label="total − start")
    figures.finish(right, "time (s)", "energy change (J)")
    title = source.parent.name
    if summary.exists():
        data = figures.summary(summary)
        title = (f"{data.get('scene')}: {data.get('method')}, K = {data.get('iterations')}, "
                 f"{data.get('substeps', 1)} substep(s) per {data.get('dt', 0):.4g} s frame")
        if data.get("diverged"):
            title += f" — unstable at frame {data.get('diverged_at_frame')}"
    figure.suptitle(title, fontsize=11)
    figure.tight_layout()
    figures.save(figure, target)


def main(out_dir):
    sources = sorted((out_dir / LAB).glob("*/per_frame.csv"))
    if not sources:
        lab_dir = out_dir / LAB
        return figures.skip("lab04_history", f"needs {lab_dir}/RUN/per_frame.csv; make it with: " + figures.make_command(
            LAB, f"--scene curtain-32 --iterations 16 --steps 90 --out {lab_dir}/curtain-32 "
            f"--summary {lab_dir}/curtain-32.json"))
    for source in sources:
        summary, target = source.parent.with_suffix(".json"), source.with_name("history.png")
        if not figures.up_to_date(target, [source, summary]):
            draw(source, summary, target)
    return 0


if __name__ == "__main__":
    figures.run(main)
