#!/usr/bin/env python3
"""Lab 08: each single run against time (per_frame.csv of `lab08_xpbd --out
DIR`) — the total stretch and the energies — and, from the run's summary, the
multipliers of the last substep per spring (λ/Δt², N; negative = tension).

One PNG per run: OUTDIR/lab08_xpbd/<run>/history.png."""
import _figures as figures
from _figures import plt

LAB = "lab08_xpbd"


def draw(source, summary_path, target):
    from matplotlib.ticker import MaxNLocator
    rows = figures.rows(source, ok_only=True)
    summary = figures.summary(summary_path)
    multipliers = summary.get("multipliers")
    panels = 3 if multipliers else 2
    figure, axes = plt.subplots(1, panels, figsize=(5.0 * panels, 4.0))
    time = figures.column(rows, "time")

    stretch = axes[0]
    stretch.plot(time, [1e3 * s for s in figures.column(rows, "total_stretch")], label="total stretch Σ(ℓ − L)")
    if "hanging_chain_stretch" in summary:
        stretch.axhline(1e3 * summary["hanging_chain_stretch"], color="k", ls="--", lw=1,
                        label="hanging at rest with its springs' k")
    figures.finish(stretch, "time (s)", "stretch (mm)")

    energy = axes[1]
    kinetic, potential = figures.column(rows, "kinetic"), figures.column(rows, "potential")
    elastic, total = figures.column(rows, "elastic"), figures.column(rows, "total_energy")
    energy.plot(time, [k - kinetic[0] for k in kinetic], label="kinetic − start")
    energy.plot(time, [p - potential[0] for p in potential], label="gravitational − start")
    if any(e != 0.0 for e in elastic):
        energy.plot(time, [e - elastic[0] for e in elastic], label="elastic ½k(ℓ − L)² − start")
    energy.plot(time, [e - total[0] for e in total], "k", lw=2, label="total − start")
    figures.finish(energy, "time (s)", "energy change (J)")

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
    figures.save(figure, target)


def main(out_dir):
    lab_dir = out_dir / LAB
    sources = sorted(lab_dir.glob("*/per_frame.csv"))
    if not sources:
        return figures.skip("lab08_history", f"needs {lab_dir}/RUN/per_frame.csv; make it with: " + figures.make_command(
            LAB, f"--scene hanging-chain-20 --iterations 512 --out {lab_dir}/hanging-chain-20 "
            f"--summary {lab_dir}/hanging-chain-20.json"))
    for source in sources:
        summary, target = source.parent.with_suffix(".json"), source.with_name("history.png")
        if not figures.up_to_date(target, [source, summary]):
            draw(source, summary, target)
    return 0


if __name__ == "__main__":
    figures.run(main)
