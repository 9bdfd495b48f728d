#!/usr/bin/env python3
"""Lab 04: strain and energy against time for each single run (per_frame.csv
of `lab04_pbd --out DIR`): how fast PBD damps, and where the energy goes.
Hard constraints store no energy, so while the mesh is stretched the total
(kinetic + potential) dips below its start and comes back as it contracts;
what stays lost is the solver's damping.

One PNG per run: OUTDIR/lab04_pbd/<run>/history.png."""
import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

LAB = "lab04_pbd"


def column(rows, name):
    return [float(r[name]) for r in rows]


def draw(source, summary):
    with open(source, newline="") as handle:
        rows = [r for r in csv.DictReader(handle) if r["status"] == "ok"]
    time = column(rows, "time")
    figure, (left, right) = plt.subplots(1, 2, figsize=(11.0, 4.0))
    max_strain, rms_strain = column(rows, "max_strain"), column(rows, "rms_strain")
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
    left.set_xlabel("time (s)")
    left.set_ylabel("strain  |l − L| / L")
    left.legend(fontsize=8)
    left.grid(True, alpha=0.3)
    kinetic, potential, total = column(rows, "kinetic"), column(rows, "potential"), column(rows, "total_energy")
    right.plot(time, [k - kinetic[0] for k in kinetic], label="kinetic − start")
    right.plot(time, [p - potential[0] for p in potential], label="potential − start")
    right.plot(time, [e - total[0] for e in total], "k", lw=2, label="total − start")
    right.set_xlabel("time (s)")
    right.set_ylabel("energy change (J)")
    right.legend(fontsize=8)
    right.grid(True, alpha=0.3)
    title = source.parent.name
    if summary.exists():
        import json

        data = json.loads(summary.read_text())
        title = (f"{data.get('scene')}: {data.get('method')}, K = {data.get('iterations')}, "
                 f"{data.get('substeps', 1)} substep(s) per {data.get('dt', 0):.4g} s frame")
        if data.get("diverged"):
            title += f" — unstable at frame {data.get('diverged_at_frame')}"
    figure.suptitle(title, fontsize=11)
    figure.tight_layout()
    target = source.with_name("history.png")
    figure.savefig(target, dpi=110)
    plt.close(figure)
    print(f"wrote {target}")


def main(out_dir):
    sources = sorted((Path(out_dir) / LAB).glob("*/per_frame.csv"))
    if not sources:
        lab_dir = Path(out_dir) / LAB
        print(f"lab04_history: needs {lab_dir}/RUN/per_frame.csv; make it with: ./course run lab04_solution "
              f"--scene curtain-32 --iterations 16 --steps 90 --out {lab_dir}/curtain-32 --summary {lab_dir}/curtain-32.json")
        return 4
    for source in sources:
        draw(source, source.parent.with_suffix(".json"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "out"))
