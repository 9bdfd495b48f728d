#!/usr/bin/env python3
"""The extremes matrix (issue 12): the outcome of every cell (finite, reported
unstable, not applicable, silent NaN) as a heat map, one panel per geometry and
iteration count; rows are the methods, columns stiffness × Δt × mass ratio.
Reads OUTDIR/bench/extremes.csv, writes OUTDIR/bench/extremes.png."""
from pathlib import Path

import _figures as figures
from _figures import plt

COMMAND = "./course extremes  (or: build/bin/extremes --out out/bench)"
OUTCOMES = ["finite", "reported", "not-applicable", "silent-nan"]
COLORS = ["#4caf50", "#ff9800", "#bdbdbd", "#d50000"]


def main(out_dir):
    bench = Path(out_dir) / "bench"
    table = bench / "extremes.csv"
    if not table.exists():
        return figures.skip("bench_extremes", f"no {table}; make it with {COMMAND}")
    target = bench / "extremes.png"
    if figures.up_to_date(target, [table]):
        return 0
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch
    rows = figures.rows(table)
    methods = list(dict.fromkeys(r["method"] for r in rows))
    geometries = list(dict.fromkeys(r["geometry"] for r in rows))
    iterations = list(dict.fromkeys(r["iterations"] for r in rows))
    stiffness = list(dict.fromkeys(r["stiffness"] for r in rows))
    dts = list(dict.fromkeys(r["dt"] for r in rows))
    ratios = list(dict.fromkeys(r["mass_ratio"] for r in rows))
    columns = [(k, dt, m) for k in stiffness for dt in dts for m in ratios]
    where = {(r["method"], r["geometry"], r["iterations"], r["stiffness"], r["dt"], r["mass_ratio"]): r["outcome"]
             for r in rows}
    figure, axes = plt.subplots(len(geometries), len(iterations), figsize=(8.5 * len(iterations),
                                                                          2.0 + 2.3 * len(geometries)),
                                squeeze=False)
    cmap = ListedColormap(COLORS)
    for gi, geometry in enumerate(geometries):
        for ii, k_iter in enumerate(iterations):
            ax = axes[gi][ii]
            grid = [[OUTCOMES.index(where.get((m, geometry, k_iter, *c), "not-applicable")) for c in columns]
                    for m in methods]
            ax.imshow(grid, cmap=cmap, vmin=-0.5, vmax=3.5, aspect="auto", interpolation="nearest")
            ax.set_yticks(range(len(methods)))
            ax.set_yticklabels(methods, fontsize=7)
            block = len(dts) * len(ratios)
            ax.set_xticks([block * i + (block - 1) / 2 for i in range(len(stiffness))])
            ax.set_xticklabels([f"k = {k if k == 'inf' else format(float(k), 'g')} N/m" for k in stiffness], fontsize=7)
            for i in range(1, len(stiffness)):
                ax.axvline(block * i - 0.5, color="black", linewidth=1.0)
            for i in range(1, len(stiffness) * len(dts)):
                if i % len(dts):
                    ax.axvline(len(ratios) * i - 0.5, color="white", linewidth=0.5)
            ax.set_title(f"{geometry}, {k_iter} iteration(s)", fontsize=9)
    dt_text = ", ".join(f"{float(d):.3g}" for d in dts)
    ratio_text = ", ".join(f"{float(m):g}" for m in ratios)
    figure.legend(handles=[Patch(color=c, label=o) for c, o in zip(COLORS, OUTCOMES)], loc="lower center", ncol=4)
    figure.suptitle(f"Outcome per cell. Within each stiffness block: Δt = {dt_text} s (left to right), each split "
                    f"into mass ratio {ratio_text}", fontsize=10)
    figure.tight_layout(rect=(0, 0.04, 1, 0.97))
    figures.save(figure, target, dpi=100)
    return 0


if __name__ == "__main__":
    figures.run(main)
