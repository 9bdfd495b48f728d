#!/usr/bin/env python3
"""Lab 09: the largest stable time step of a heavy chain against its mass
ratio, with and without the geometric stiffness (stability.csv and
stability_runs.csv of `lab09_stable_constrained --sweep-mass-ratios ... --out DIR`).
Every step size tried is a marker (filled: stable, cross: unstable); the
lines join the largest stable step per ratio; the dashed line is the
driver's 2/omega_max, where symplectic Euler on the chain's sideways
vibrations stops being stable.

Writes OUTDIR/lab09_stable_constrained/stability.png."""
from pathlib import Path

import _figures as figures
from _figures import plt

LAB = "lab09_stable_constrained"
COMMAND = "./course demo lab09 (or ./course run lab09 --sweep-mass-ratios 1,10,100,1000,10000,100000,1000000 --out out/lab09_stable_constrained)"
STYLE = {"off": ("tab:red", "without K_g (lab 07)"), "on": ("tab:blue", "with K_g")}


def main(out_dir):
    folder = Path(out_dir) / LAB
    limits_path, runs_path = folder / "stability.csv", folder / "stability_runs.csv"
    for path in (limits_path, runs_path):
        if not path.exists():
            return figures.skip("lab09_stability", f"no {path} (make it with {COMMAND})")
    limits, runs = figures.rows(limits_path), figures.rows(runs_path)
    if not limits:
        return figures.skip("lab09_stability", f"{limits_path} has no rows (make it with {COMMAND})")
    target = folder / "stability.png"
    if figures.up_to_date(target, [limits_path, runs_path]):
        return 0
    from matplotlib.lines import Line2D

    figure, axes = plt.subplots(figsize=(7.5, 5.8))
    arrows = []
    offsets = {"off": 0.93, "on": 1.07}  # side by side, so both modes' markers show
    for mode, (colour, label) in STYLE.items():
        rows = [r for r in limits if r["geometric_stiffness"] == mode]
        if not rows:
            continue
        ratio = [float(r["mass_ratio"]) for r in rows]
        largest = [figures.number(r["largest_stable_dt"]) for r in rows]
        points = [(x, y) for x, y in zip(ratio, largest) if y is not None]
        if points:
            axes.loglog(*zip(*points), "-", color=colour, lw=2, label=f"largest stable Δt, {label}")
        # Stable up to the largest step tried: an arrow, the limit is above.
        never = [(float(r["mass_ratio"]), y) for r, y in zip(rows, largest)
                 if y is not None and r["first_unstable_dt"] == ""]
        for x, y in never:
            axes.annotate("", xy=(x, y * 1.6), xytext=(x, y), arrowprops={"arrowstyle": "->", "color": colour})
        if never:  # in the legend: over the plot, the words covered the markers (issue 25)
            arrows.append((Line2D([], [], color=colour, marker="$\\uparrow$", ms=10, ls=""),
                           f"no unstable Δt up to the largest tried, {label}"))
        tried = [r for r in runs if r["geometric_stiffness"] == mode]
        stable = [(float(r["mass_ratio"]) * offsets[mode], float(r["dt"])) for r in tried if r["stable"] == "1"]
        unstable = [(float(r["mass_ratio"]) * offsets[mode], float(r["dt"])) for r in tried if r["stable"] != "1"]
        if stable:
            axes.loglog(*zip(*stable), "o", ms=3, color=colour, alpha=0.35)
        if unstable:
            axes.loglog(*zip(*unstable), "x", ms=7, mew=2, color=colour)
    predicted = sorted({(float(r["mass_ratio"]), float(r["predicted_dt_without"])) for r in limits})
    axes.loglog(*zip(*predicted), "k--", lw=1, label="2/ω_max of the sideways vibrations")
    first = limits[0]
    axes.set_xlabel("mass ratio (bottom mass / bead mass)")
    axes.set_ylabel("time step Δt (s)")
    axes.set_title(f"heavy chain, {first['links']} hard links, {first['steps']} steps per run, "
                   f"method {first['method']}", fontsize=10)
    axes.grid(True, which="both", alpha=0.3)
    handles, labels = axes.get_legend_handles_labels()
    handles += [handle for handle, _ in arrows]
    labels += [text for _, text in arrows]
    axes.legend(handles, labels, fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2,
                frameon=False)
    figure.tight_layout()
    figures.save(figure, target)
    return 0


if __name__ == "__main__":
    figures.run(main)
