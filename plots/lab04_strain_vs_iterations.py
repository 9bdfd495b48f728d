#!/usr/bin/env python3
"""Lab 04, experiment 1: the hanging curtain's steady strain against the
iteration count K, one curve per resolution (from `lab04_pbd
--sweep-iterations ... --sweep-scenes curtain-8,...`, strain_vs_iterations.csv).

Filled markers: the run settled; hollow: it had not settled when it stopped;
a cross on the top edge: the run was unstable (the program stopped it)."""
from collections import defaultdict

import _figures as figures
from _figures import plt

LAB = "lab04_pbd"


def read_runs(path):
    runs = defaultdict(list)
    for row in figures.rows(path):
        runs[(int(row["particles"]), row["scene"])].append(row)
    return dict(sorted(runs.items()))


def draw(axes, runs, column, label, reference=False):
    top = max((figures.number(r[column]) or 0.0) for rows in runs.values() for r in rows) * 3.0
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for index, (colour, ((_, scene), rows)) in enumerate(zip(colours, runs.items())):
        nx = rows[0]["nx"]
        k = [int(r["iterations"]) for r in rows if figures.number(r[column]) is not None]
        y = [figures.number(r[column]) for r in rows if figures.number(r[column]) is not None]
        axes.loglog(k, y, "-", color=colour, label=f"{scene} ({nx}² particles)")
        for r in rows:
            value = figures.number(r[column])
            if value is None and r["status"].startswith("diverged"):
                axes.plot(int(r["iterations"]), top * 1.6 ** index, "x", color=colour, ms=8, mew=2, clip_on=False)
            elif value is not None:
                settled = r["status"] == "settled"
                axes.plot(int(r["iterations"]), value, "o", color=colour, ms=5,
                          mfc=colour if settled else "white")
    if reference:  # a 1/K line through the coarsest curtain's value at K = 8
        rows = next(iter(runs.values()))
        at_8 = [figures.number(r[column]) for r in rows if r["iterations"] == "8" and figures.number(r[column])]
        if at_8:
            axes.loglog([1, 128], [at_8[0] * 8, at_8[0] * 8 / 128], ":", color="0.5", label="∝ 1/K")
    axes.plot([], [], "o", color="0.4", label="settled")
    axes.plot([], [], "o", color="0.4", mfc="white", label="not settled (stopped at the time limit)")
    axes.plot([], [], "x", color="0.4", mew=2, label="unstable (reported by the program)")
    every_k = sorted({int(r["iterations"]) for rows in runs.values() for r in rows})
    axes.set_xscale("log", base=2)
    axes.set_xticks(every_k)
    axes.set_xticklabels([str(k) for k in every_k])
    axes.set_xlabel("iterations per step K (Gauss-Seidel sweeps)")
    axes.set_ylabel(label)
    axes.grid(True, which="major", alpha=0.3)
    return top


def main(out_dir):
    source = out_dir / LAB / "strain_vs_iterations.csv"
    if not source.exists():
        return figures.skip("lab04_strain_vs_iterations", f"needs {source}; make it with: " + figures.make_command(
            LAB, "--sweep-iterations 1,2,4,8,16,32,64,128 --sweep-scenes curtain-8,curtain-16,curtain-32,curtain-64 "
            f"--steps 3600 --out {source.parent}"))
    target, table = source.with_name("strain_vs_iterations.png"), source.with_name("strain_vs_iterations.md")
    if figures.up_to_date([target, table], [source]):
        return 0
    runs = read_runs(source)
    first = next(iter(runs.values()))[0]
    figure, (left, right) = plt.subplots(1, 2, figsize=(11.5, 5.2))
    draw(left, runs, "steady_max_strain", "steady max strain  max |l − L| / L", reference=True)
    draw(right, runs, "steady_rms_strain", "steady RMS strain over all springs")
    handles, labels = left.get_legend_handles_labels()
    figure.legend(handles, labels, loc="lower center", ncol=4, fontsize=8, frameon=False)
    left.set_title("Max strain (at the pinned corners)", fontsize=10)
    right.set_title("RMS strain (the whole cloth)", fontsize=10)
    figure.suptitle(f"Hanging curtain, PBD: the stiffness is made by the solver "
                    f"(Δt = {float(first['dt']):.4g} s, {first['substeps']} substep, "
                    f"steady = mean over the last {float(first['window_seconds']):.3g} s)", fontsize=11)
    figure.tight_layout(rect=(0, 0.11, 1, 1))
    figures.save(figure, target, dpi=120)
    figures.write_table(table, markdown_table(runs))
    return 0


def markdown_table(runs):
    """Steady max strain (RMS in brackets) per K and resolution, for the handout."""
    every_k = sorted({int(r["iterations"]) for rows in runs.values() for r in rows})
    lines = ["| K | " + " | ".join(f"{rows[0]['nx']}² ({scene})" for (_, scene), rows in runs.items()) + " |",
             "|---:|" + "---:|" * len(runs)]
    for k in every_k:
        cells = []
        for rows in runs.values():
            row = next((r for r in rows if int(r["iterations"]) == k), None)
            if row is None:
                cells.append("")
            elif row["status"].startswith("diverged"):
                cells.append("unstable")
            else:
                cell = f"{float(row['steady_max_strain']):.3g} ({float(row['steady_rms_strain']):.2g})"
                cells.append(cell + ("" if row["status"] == "settled" else " not settled"))
        lines.append(f"| {k} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    figures.run(main)
