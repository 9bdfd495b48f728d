#!/usr/bin/env python3
"""Lab 08: each single run against time (per_frame.csv of `lab08_xpbd --out
DIR`) — the total stretch and the energies — and, from the run's summary, the
multipliers of the last substep per spring (λ/Δt², N; negative = tension).

One PNG per run: OUTDIR/lab08_xpbd/<run>/history.png."""
import csv
import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

LAB = "lab08_xpbd"


def column(rows, name):
    return [float(r[name]) for r in rows]


def draw(source, summary_path):
    with open(source, newline="") as handle:
        rows = [r for r in csv.DictReader(handle) if r["status"] == "ok"]
    summary = json.loads(summary_path.read_text()) if summary_path.exists() else {}
    multipliers = summary.get("multipliers")
    panels = 3 if multipliers else 2
    figure, axes = plt.subplots(1, panels, figsize=(5.0 * panels, 4.0))
    time = column(rows, "time")

    stretch = axes[0]
    stretch.plot(time, [1e3 * s for s in column(rows, "total_stretch")], label="total stretch Σ(ℓ − L)")
    if "hanging_chain_stretch" in summary:
        stretch.axhline(1e3 * summary["hanging_chain_stretch"], color="k", ls="--", lw=1,
                        label="hanging at rest with its springs' k")
    stretch.set_xlabel("time (s)")
    stretch.set_ylabel("stretch (mm)")
    stretch.legend(fontsize=8)
    stretch.grid(True, alpha=0.3)

    energy = axes[1]
    kinetic, potential = column(rows, "kinetic"), column(rows, "potential")
    elastic, total = column(rows, "elastic"), column(rows, "total_energy")
    energy.plot(time, [k - kinetic[0] for k in kinetic], label="kinetic − start")
    energy.plot(time, [p - potential[0] for p in potential], label="gravitational − start")
    if any(e != 0.0 for e in elastic):
        energy.plot(time, [e - elastic[0] for e in elastic], label="elastic ½k(ℓ − L)² − start")
    energy.plot(time, [e - total[0] for e in total], "k", lw=2, label="total − start")
    energy.set_xlabel("time (s)")
    energy.set_ylabel("energy change (J)")
    energy.legend(fontsize=8)
    energy.grid(True, alpha=0.3)

    if multipliers:
        bars = axes[2]
        bars.bar(range(len(multipliers)), multipliers, color="C3", width=0.8 if len(multipliers) < 60 else 1.0)
        bars.set_xlim(-1, len(multipliers))
        bars.xaxis.set_major_locator(MaxNLocator(integer=True))
        bars.set_xlabel("spring (file order)")
        bars.set_ylabel(f"multiplier λ/Δt² ({summary.get('multipliers_unit', 'N')}), < 0 is tension")
        bars.set_title("last substep", fontsize=9)
        bars.grid(True, axis="y", alpha=0.3)

    title = source.parent.name
    if summary:
        title = (f"{summary.get('scene')}: {summary.get('method')}, K = {summary.get('iterations')}, "
                 f"{summary.get('substeps', 1)} substep(s) per {summary.get('dt', 0):.4g} s frame")
        if summary.get("diverged"):
            title += f" — unstable at frame {summary.get('diverged_at_frame')}"
    figure.suptitle(title, fontsize=11)
    figure.tight_layout()
    target = source.with_name("history.png")
    figure.savefig(target, dpi=110)
    plt.close(figure)
    print(f"wrote {target}")


def main(out_dir):
    lab_dir = Path(out_dir) / LAB
    sources = sorted(lab_dir.glob("*/per_frame.csv"))
    if not sources:
        print(f"lab08_history: needs {lab_dir}/RUN/per_frame.csv; make it with: ./course run lab08_solution "
              f"--scene hanging-chain-20 --iterations 512 --out {lab_dir}/hanging-chain-20 "
              f"--summary {lab_dir}/hanging-chain-20.json")
        return 4
    for source in sources:
        draw(source, source.parent.with_suffix(".json"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "out"))
