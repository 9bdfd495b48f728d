#!/usr/bin/env python3
"""Lab 07, experiment 1: constraint drift at C = 0. The 20-link hard chain
(ragdoll-chain-20) released from the horizontal, solved by the Schur
complement: max |phi| after every step against time, at dt = 1/60 s, with the
post-step projection (--stabilize), and at dt = 1/240 s. Right: the wall time
per simulated second of each run, split into the solve and the projection.

Reads OUTDIR/lab07_constrained_dynamics/{drift,drift-stabilized,drift-dt4}/per_frame.csv
and writes drift.png beside them."""
import _figures as figures
from _figures import plt

LAB = "lab07_constrained_dynamics"
RUNS = [
    ("drift", "dt = 1/60 s"),
    ("drift-stabilized", "dt = 1/60 s + projection (--stabilize)"),
    ("drift-dt4", "dt = 1/240 s"),
]
MAKE = ("./course demo lab07   (or: ./course run lab07 --scene ragdoll-chain-20 [--stabilize | "
        "--dt 0.004166666666666667 --steps 1200] --out OUT/lab07_constrained_dynamics/RUN)")


def main(out_dir):
    folder = out_dir / LAB
    sources = [folder / run / "per_frame.csv" for run, _ in RUNS]
    for source in sources:
        if not source.is_file():
            return figures.skip("lab07_drift", f"{source}: missing; make it with {MAKE}")
    target = folder / "drift.png"
    if figures.up_to_date(target, sources):
        return 0
    figure, (left, right) = plt.subplots(1, 2, figsize=(12.0, 4.2), gridspec_kw={"width_ratios": [2, 1]})
    names, solve_ms, projection_ms = [], [], []
    for run, label in RUNS:
        rows = [r for r in figures.rows(folder / run / "per_frame.csv", ok_only=True) if int(r["frame"]) > 0]
        time = [float(r["time"]) for r in rows]
        error = [max(float(r["max_constraint_error"]), 1e-17) for r in rows]
        left.semilogy(time, error, lw=1.2, label=f"{label}: worst {max(error):.2g} m")
        names.append(label.replace(" + ", "\n+ "))
        simulated = time[-1] if time else 1.0
        solve_ms.append(1e3 * sum(float(r["step_seconds"]) for r in rows) / simulated)
        projection_ms.append(1e3 * sum(float(r["stabilize_seconds"]) for r in rows) / simulated)
    left.set_xlabel("time (s)")
    left.set_ylabel("max |φ| over the links (m)")
    left.set_title("ragdoll-chain-20, C = 0 (links of 0.05 m): drift of the linearised constraint")
    left.grid(True, which="both", alpha=0.3)
    left.legend(fontsize=8)
    positions = range(len(names))
    right.bar(positions, solve_ms, label="step (Schur solve)")
    right.bar(positions, projection_ms, bottom=solve_ms, label="projection")
    right.set_xticks(list(positions))
    right.set_xticklabels(names, fontsize=7)
    right.set_ylabel("wall time per simulated second (ms)")
    right.set_title("cost")
    right.legend(fontsize=8)
    figure.tight_layout()
    figures.save(figure, target)
    return 0


if __name__ == "__main__":
    figures.run(main)
