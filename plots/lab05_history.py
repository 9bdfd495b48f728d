#!/usr/bin/env python3
"""Lab 05: strain and energy against time for each single run (per_step.csv of
`lab05_strain_limiting --out DIR`): the largest and smallest spring strain
against the band, and where the energy goes (kinetic, elastic, gravity). A
limiter's position correction becomes velocity, (x' − x̃)/Δt, which the energy
panel shows.

One PNG per run: OUTDIR/lab05_strain_limiting/<run>/history.png."""
import _figures as figures
from _figures import plt

LAB = "lab05_strain_limiting"
COMMAND = figures.make_command(LAB, "--scene stiff-curtain-32 --limit springs "
                               "--out out/lab05_strain_limiting/stiff-springs (or ./course demo lab05)")


def draw(source, summary, target):
    rows = figures.rows(source, ok_only=True)
    if not rows:
        return
    time = figures.column(rows, "time")
    figure, (left, right) = plt.subplots(1, 2, figsize=(11.0, 4.6))
    left.plot(time, figures.column(rows, "max_strain"), label="max strain")
    left.plot(time, figures.column(rows, "min_strain"), label="min strain")
    title = source.parent.name
    if summary.exists():
        data = figures.summary(summary)
        if data.get("limit") != "none":
            for bound in (data.get("sigma_min"), data.get("sigma_max")):
                left.axhline(bound - 1.0, color="k", ls="--", lw=0.8)
        title = (f"{data.get('scene')}: limit {data.get('limit')}, K = {data.get('iterations')}, "
                 f"Δt = {data.get('dt', 0):.4g} s")
        if data.get("diverged"):
            title += f" — unstable at step {data.get('diverged_at_step')}"
    left.set_xlabel("time (s)")
    left.set_ylabel("spring strain  l/L − 1")
    left.legend(fontsize=8)
    left.grid(True, alpha=0.3)
    kinetic, elastic, potential = figures.column(rows, "kinetic"), figures.column(rows, "elastic"), figures.column(rows, "potential")
    total = figures.column(rows, "total_energy")
    right.plot(time, kinetic, label="kinetic")
    right.plot(time, elastic, label="elastic")
    right.plot(time, [p - potential[0] for p in potential], label="gravity − start")
    right.plot(time, total, "k", lw=2, label="total (gravity zero at the origin)")
    right.set_xlabel("time (s)")
    right.set_ylabel("energy (J)")
    if max(max(kinetic), max(elastic)) > 100 * max(min(abs(t) for t in total), 1e-12):
        right.set_yscale("symlog", linthresh=1e-2)
    # Below the panel: inside it, the legend would cover the total energy (issue 25).
    right.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2, frameon=False)
    right.grid(True, alpha=0.3)
    figure.suptitle(title, fontsize=11)
    figure.tight_layout()
    figures.save(figure, target)


def main(out_dir):
    sources = sorted((out_dir / LAB).glob("*/per_step.csv"))
    if not sources:
        return figures.skip("lab05_history", f"no {out_dir / LAB}/*/per_step.csv (make one with {COMMAND})")
    for source in sources:
        summary, target = source.parent.with_suffix(".json"), source.with_name("history.png")
        if not figures.up_to_date(target, [source, summary]):
            draw(source, summary, target)
    return 0


if __name__ == "__main__":
    figures.run(main)
