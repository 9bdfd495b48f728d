#!/usr/bin/env python3
"""The extremes matrix (issues 12 and 34): the outcome of every cell (finite,
reported unstable, not applicable, silent NaN, a particle left inside a
collider) as a heat map, one panel per geometry and iteration count; rows are
the methods (for lab 14's contact cells: method, colliders, speed and
friction), columns stiffness × Δt × mass ratio. Reads OUTDIR/bench/extremes.csv,
writes OUTDIR/bench/extremes.png and, when the run had contact cells,
OUTDIR/bench/extremes_contact.png."""
from pathlib import Path

import _figures as figures
from _figures import plt

COMMAND = "./course extremes  (or: build/bin/extremes --out out/bench)"
OUTCOMES = ["finite", "reported", "not-applicable", "silent-nan", "inside"]
COLORS = ["#4caf50", "#ff9800", "#bdbdbd", "#d50000", "#6a1b9a"]


def row_label(r):
    """The heat map's row of a cell: its method, and for a contact cell its colliders, speed and μ."""
    if r.get("colliders", "none") == "none":
        return r["method"]
    return f"{r['method']} {r['colliders']} {r['speed']} μ={float(r['friction']):g}"


def draw(rows, target, title):
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch
    labels = list(dict.fromkeys(row_label(r) for r in rows))
    geometries = list(dict.fromkeys(r["geometry"] for r in rows))
    iterations = list(dict.fromkeys(r["iterations"] for r in rows))
    stiffness = list(dict.fromkeys(r["stiffness"] for r in rows))
    dts = list(dict.fromkeys(r["dt"] for r in rows))
    ratios = list(dict.fromkeys(r["mass_ratio"] for r in rows))
    columns = [(k, dt, m) for k in stiffness for dt in dts for m in ratios]
    where = {(row_label(r), r["geometry"], r["iterations"], r["stiffness"], r["dt"], r["mass_ratio"]): r["outcome"]
             for r in rows}
    height = 2.0 + (0.9 + 0.12 * len(labels)) * len(geometries)
    figure, axes = plt.subplots(len(geometries), len(iterations), figsize=(8.5 * len(iterations), height),
                                squeeze=False)
    cmap = ListedColormap(COLORS)
    for gi, geometry in enumerate(geometries):
        for ii, k_iter in enumerate(iterations):
            ax = axes[gi][ii]
            # A cell the run did not have (the quick subset) is drawn as not applicable.
            grid = [[OUTCOMES.index(where.get((m, geometry, k_iter, *c), "not-applicable")) for c in columns]
                    for m in labels]
            ax.imshow(grid, cmap=cmap, vmin=-0.5, vmax=len(OUTCOMES) - 0.5, aspect="auto", interpolation="nearest")
            ax.set_yticks(range(len(labels)))
            ax.set_yticklabels(labels, fontsize=7 if len(labels) < 30 else 5)
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
    figure.legend(handles=[Patch(color=c, label=o) for c, o in zip(COLORS, OUTCOMES)], loc="lower center",
                  ncol=len(OUTCOMES))
    figure.suptitle(f"{title}. Within each stiffness block: Δt = {dt_text} s (left to right), each split "
                    f"into mass ratio {ratio_text}", fontsize=10)
    figure.tight_layout(rect=(0, 0.04, 1, 0.97))
    figures.save(figure, target, dpi=100)


def main(out_dir):
    bench = Path(out_dir) / "bench"
    table = bench / "extremes.csv"
    if not table.exists():
        return figures.skip("bench_extremes", f"no {table}; make it with {COMMAND}")
    target = bench / "extremes.png"
    contact_target = bench / "extremes_contact.png"
    rows = figures.rows(table)
    springs = [r for r in rows if r.get("colliders", "none") == "none"]
    contact = [r for r in rows if r.get("colliders", "none") != "none"]
    targets = ([target] if springs else []) + ([contact_target] if contact else [])
    if all(figures.up_to_date(t, [table]) for t in targets):
        return 0
    if springs:
        draw(springs, target, "Outcome per cell")
    if contact:
        draw(contact, contact_target, "Lab 14's contact cells (colliders under the curtain)")
    return 0


if __name__ == "__main__":
    figures.run(main)
