#!/usr/bin/env python3
"""Lab 05: strain and energy against time for each single run (per_step.csv of
`lab05_strain_limiting --out DIR`): the largest and smallest spring strain
against the band, and where the energy goes (kinetic, elastic, gravity). A
limiter's position correction becomes velocity, (x' − x̃)/Δt, which the energy
panel shows.

One PNG per run: OUTDIR/lab05_strain_limiting/<run>/history.png."""
import csv
import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

LAB = "lab05_strain_limiting"
COMMAND = ("./course run lab05_solution --scene stiff-curtain-32 --limit springs "
           "--out out/lab05_strain_limiting/stiff-springs (or ./course demo)")


def column(rows, name):
    return [float(r[name]) for r in rows]


def draw(source, summary):
    with open(source, newline="") as handle:
        rows = [r for r in csv.DictReader(handle) if r["status"] == "ok"]
    if not rows:
        return
    time = column(rows, "time")
    figure, (left, right) = plt.subplots(1, 2, figsize=(11.0, 4.0))
    left.plot(time, column(rows, "max_strain"), label="max strain")
    left.plot(time, column(rows, "min_strain"), label="min strain")
    title = source.parent.name
    if summary.exists():
        data = json.loads(summary.read_text())
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
    kinetic, elastic, potential = column(rows, "kinetic"), column(rows, "elastic"), column(rows, "potential")
    total = column(rows, "total_energy")
    right.plot(time, kinetic, label="kinetic")
    right.plot(time, elastic, label="elastic")
    right.plot(time, [p - potential[0] for p in potential], label="gravity − start")
    right.plot(time, total, "k", lw=2, label="total (gravity zero at the origin)")
    right.set_xlabel("time (s)")
    right.set_ylabel("energy (J)")
    if max(max(kinetic), max(elastic)) > 100 * max(min(abs(t) for t in total), 1e-12):
        right.set_yscale("symlog", linthresh=1e-2)
    right.legend(fontsize=8)
    right.grid(True, alpha=0.3)
    figure.suptitle(title, fontsize=11)
    figure.tight_layout()
    target = source.with_name("history.png")
    figure.savefig(target, dpi=110)
    plt.close(figure)
    print(f"wrote {target}")


def main(out_dir):
    sources = sorted((Path(out_dir) / LAB).glob("*/per_step.csv"))
    if not sources:
        print(f"lab05_history: no {Path(out_dir) / LAB}/*/per_step.csv (make one with {COMMAND})")
        return 4
    for source in sources:
        draw(source, source.parent.with_suffix(".json"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "out"))
