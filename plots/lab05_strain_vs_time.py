#!/usr/bin/env python3
"""Lab 05, experiment 1: the soft curtain once per limiter at the same K (from
`lab05_strain_limiting --compare-limits none,springs,triangles-area,triangles-stretch`):

- strain_vs_time.png — the largest spring strain l/L − 1 against time, one
  curve per limiter, with the band and the 0.5/K tolerance; beside it the
  wall time per step of each limiter (the price of the bound);
- shapes.png — the curtain after the run, every spring coloured by its strain.

Input: OUTDIR/lab05_strain_limiting/{strain_vs_time,compare_limits,shapes}.csv."""
from collections import defaultdict

import _figures as figures
from _figures import plt

LAB = "lab05_strain_limiting"
COMMAND = figures.make_command(LAB, "--scene soft-curtain-32 --compare-limits "
                               "none,springs,triangles-area,triangles-stretch --steps 800 "
                               "--out out/lab05_strain_limiting (or ./course demo lab05)")


def draw_strain(series, table, target):
    by_limit = defaultdict(list)
    for row in series:
        by_limit[row["limit"]].append(row)
    first = table[0]
    sigma_max, iterations = float(first["sigma_max"]), int(first["iterations"])
    figure, (left, right) = plt.subplots(1, 2, figsize=(12.0, 4.4), gridspec_kw={"width_ratios": [2.2, 1]})
    for limit, rows in by_limit.items():
        rows = [r for r in rows if r["status"] == "ok" and int(r["step"]) > 0]
        left.semilogy([float(r["time"]) for r in rows], [max(float(r["max_strain"]), 1e-4) for r in rows],
                      label=limit, lw=1.2)
    left.axhline(sigma_max - 1.0, color="k", ls="--", lw=1, label=f"σ_max − 1 = {sigma_max - 1:g}")
    if iterations > 0:
        left.axhline(sigma_max - 1.0 + 0.5 / iterations, color="0.4", ls=":", lw=1,
                     label=f"+ 0.5/K (K = {iterations}): the tests' tolerance")
    left.set_xlabel("time (s)")
    left.set_ylabel("max spring strain  l/L − 1")
    left.set_ylim(1e-3, None)
    left.grid(True, which="both", alpha=0.3)
    left.legend(fontsize=8)
    left.set_title(f"{first['scene']}: Δt = {float(first['dt']):g} s, K = {iterations}", fontsize=10)

    names = [r["limit"] for r in table]
    per_step = [float(r["seconds_per_step"]) for r in table]
    bars = right.bar(range(len(names)), per_step, color=[f"C{i}" for i in range(len(names))])
    right.set_yscale("log")
    right.set_xticks(range(len(names)))
    right.set_xticklabels(names, rotation=20, fontsize=8)
    right.set_ylabel("wall time per step (s)")
    for bar, row in zip(bars, table):
        right.text(bar.get_x() + bar.get_width() / 2, bar.get_height(), f"max {float(row['max_strain_over_run']):.3g}",
                   ha="center", va="bottom", fontsize=8)
    right.set_title("cost per step (label: max strain over the run)", fontsize=10)
    right.grid(True, axis="y", which="both", alpha=0.3)
    figure.tight_layout()
    figures.save(figure, target)


def draw_shapes(shapes, table, target):
    from matplotlib.collections import LineCollection
    from matplotlib.colors import TwoSlopeNorm
    by_limit = defaultdict(list)
    for row in shapes:
        by_limit[row["limit"]].append(row)
    limits = [r["limit"] for r in table if r["limit"] in by_limit]
    if not limits:
        return
    sigma_max = float(table[0]["sigma_max"])
    # Three band widths either way, so that strains at the band are clearly
    # coloured; beyond that the colour saturates (the titles give the max).
    top = 3.0 * max(sigma_max - 1.0, 1e-3)
    norm = TwoSlopeNorm(vmin=-top, vcenter=0.0, vmax=top)
    figure, axes = plt.subplots(1, len(limits), figsize=(3.3 * len(limits) + 1.0, 4.0), squeeze=False, sharey=True)
    collection = None
    for axis, limit in zip(axes[0], limits):
        rows = by_limit[limit]
        segments = [((float(r["x_i"]), float(r["y_i"])), (float(r["x_j"]), float(r["y_j"]))) for r in rows]
        collection = LineCollection(segments, cmap="coolwarm", norm=norm, linewidths=0.9)
        collection.set_array([float(r["strain"]) for r in rows])
        axis.add_collection(collection)
        axis.autoscale()
        axis.set_aspect("equal")
        worst = max(float(r["strain"]) for r in rows)
        axis.set_title(f"{limit}\nmax strain {worst:.3g}", fontsize=9)
        axis.set_xlabel("x (m)")
    axes[0][0].set_ylabel("y (m)")
    figure.colorbar(collection, ax=axes[0].tolist(), extend="both",
                    label=f"strain l/L − 1 (band up to {sigma_max - 1:g})")
    figure.suptitle(f"{table[0]['scene']} after {float(table[0]['dt']) * int(table[0]['steps_done']):g} s", fontsize=10)
    figures.save(figure, target)


def main(out_dir):
    folder = out_dir / LAB
    paths = [folder / "strain_vs_time.csv", folder / "compare_limits.csv", folder / "shapes.csv"]
    for path in paths:
        if not path.is_file():
            return figures.skip("lab05_strain_vs_time", f"no {path} (make it with {COMMAND})")
    if not figures.up_to_date(folder / "strain_vs_time.png", paths[:2]):
        draw_strain(figures.rows(paths[0]), figures.rows(paths[1]), folder / "strain_vs_time.png")
    if not figures.up_to_date(folder / "shapes.png", paths[1:]):
        draw_shapes(figures.rows(paths[2]), figures.rows(paths[1]), folder / "shapes.png")
    return 0


if __name__ == "__main__":
    figures.run(main)
